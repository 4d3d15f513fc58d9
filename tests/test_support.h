// Helpers shared by the tests: where scenes live, and a renderer with validation that fails on messages.
#pragma once

#include <cstdint>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat::testing {

// The small real scenes bundled in this repository (always present).
std::filesystem::path bundled_scene_dir();
std::filesystem::path bundled_playbot();  // scenes/playbot_lod3/playbot_lod3_31000_sh2.ply
std::filesystem::path bundled_playbot_cameras();
std::filesystem::path bundled_sh3();  // scenes/playcanvas_test/playcanvas_test_64_sh3.ply
std::filesystem::path bundled_sh3_cameras();

// ../shared/scenes, or $TILESPLAT_SHARED_SCENES. Empty path when absent: callers skip
// (TILESPLAT_SKIP_OR_FAIL).
std::filesystem::path shared_scenes();

// Whether a test whose inputs or tools are missing must fail rather than skip: TILESPLAT_NO_SKIPS is
// set (to anything but "" or "0"), as .ci/run sets it, so that nothing CI must run can pass by skipping.
bool skips_forbidden();

// A pinhole camera at the origin looking down +z (camera axes = world axes, identity rotation), square
// pixels of focal length `focal`, the principal point at the image centre.
Camera axis_camera(int width, int height, double focal);

// Replays the regression inputs of one fuzzer (tests/fuzz/regressions/READER/), each once and whole,
// through `harness`, the fuzzer's own LLVMFuzzerTestOneInput linked into the test (a broken invariant
// aborts the process, which fails the test); expects at least `at_least` of them.
void replay_fuzz_regressions(const std::string& reader, size_t at_least,
                             int (*harness)(const uint8_t*, size_t));

// A directory unique to the running test for temporary files (removed by the OS, not by tests).
std::filesystem::path temp_dir();

// Writes `bytes` to temp_dir() / folder / name (the folder made) and returns the path.
std::filesystem::path write_temp_file(const std::string& folder, const std::string& name, const std::string& bytes);

// `scene` at SH degree `degree` <= its own: each Gaussian's first (degree + 1)^2 coefficients.
GaussianScene with_sh_degree(const GaussianScene& scene, int degree);

// A file read part by part (SceneInParts::open) against load_scene of it: the same report (format, Gaussians in
// the file), the same Gaussians bit for bit (for files without NaN), and `camera`'s frame rendered in parts
// under a memory budget that makes a few of them (a 64x48 camera: 274 KiB) the whole frame's.
void expect_read_in_parts_as_whole(const std::filesystem::path& path, const Camera& camera);

// A binary glTF (.glb) of `json_text` and `bin` (each padded to 4 bytes, as the GLB chunks must be).
std::string glb_bytes(std::string json_text, std::string bin);

// Expects load_scene(path) to throw one SceneError that names the file and says each of `phrases`.
void expect_scene_error(const std::filesystem::path& path, std::initializer_list<std::string> phrases);

// One renderer per test binary with the Khronos validation layer on (the layer being absent
// is itself a failure). Tests assert validation_messages() == 0 after rendering.
Renderer& validated_renderer();

// The composite picks a 16-pixel column per invocation on CPU drivers and one pixel per invocation
// on GPUs (TILESPLAT_COMPOSITE_PIXELS overrides it), and CPU drivers read and write through texel
// buffers (TILESPLAT_TEXEL_BUFFERS overrides it). Renders the scene once in each layout (1 pixel per
// invocation; 4 with texel buffers; 16 without and with), each with a fresh validated renderer, and
// expects them to agree bit for bit (rgba, depth, splat counts) and the validation layer to stay silent.
// With a RenderSettings::memory_budget the scene may render in parts, in every layout.
void expect_composite_layouts_identical(const GaussianScene& scene, const Camera& camera,
                                        const RenderSettings& settings = {});

// The GPU against the float64 reference, allowing for the cut-offs. Both stop blending a pixel before
// the splat that would take its transmittance below AccuracyModes::transmittance_cutoff and skip splats
// fainter than alpha_cutoff; a splat within float rounding of either threshold can fall on the other
// side on the GPU, and the pixel then differs by that one splat (its count by one, its colour by up to
// the transmittance left). How often depends on the driver's float rounding: none of the test scenes'
// pixels does on Mesa 22's lavapipe, a few do on Mesa 25's. `agreeing` compares the pixels whose splat
// counts agree (there the two agree to float rounding); the others are counted and measured apart.
struct CutoffAwareDifference {
  ImageDifference agreeing;      // over the pixels with equal splat counts (the others set equal)
  size_t flipped = 0;            // pixels whose splat count differs
  uint32_t flipped_splats = 0;   // the largest |count difference| among them
  double flipped_max_abs = 0;    // the largest |difference| in any channel among them, alpha included
};
// Needs splat counts in both images (RenderSettings::splat_count, the default).
CutoffAwareDifference compare_allowing_cutoff_flips(const RenderImage& gpu, const RenderImage& reference);

// The largest |a[i] - b[i]| over two arrays of the same length (0 for empty ones).
float max_abs_difference(const std::vector<float>& a, const std::vector<float>& b);

// Expects two scenes to hold the same Gaussians, bit for bit: every array and the SH degree (the rotations
// unless `rotations` is false, for a caller that compares them to a tolerance).
void expect_identical_scenes(const GaussianScene& actual, const GaussianScene& expected,
                             bool rotations = true);
// The usual bounds: agreeing pixels within `max_abs` (colour and alpha), at most one pixel in 1,000
// flipped, each by one splat and by less than 1/64 (a splat's whole contribution stays below that at
// the cut-offs only because the transmittance left there is small).
void expect_matches_reference(const RenderImage& gpu, const RenderImage& reference, double max_abs,
                              const std::string& what);

// An 8-bit PNG read back as RGB through libpng's simplified API (throws std::runtime_error).
struct DecodedPng {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgb;
};
DecodedPng read_png_rgb(const std::filesystem::path& path);

// The message of the exception of type E (or derived) that `action` throws, for tests of error
// messages; "(no exception)" when it throws none. An exception of another type escapes to the test.
template <typename E = std::exception, typename Action>
std::string error_of(Action&& action) {
  try {
    action();
  } catch (const E& error) {
    return error.what();
  }
  return "(no exception)";
}

}  // namespace tilesplat::testing

// Skips the test, saying why (`message` may stream: a << " b"), or fails it where skips are forbidden
// (skips_forbidden(): CI). Like GTEST_SKIP, it returns from the test body.
#define TILESPLAT_SKIP_OR_FAIL(message)                                                        \
  do {                                                                                         \
    if (::tilesplat::testing::skips_forbidden())                                               \
      GTEST_FAIL() << message << " (TILESPLAT_NO_SKIPS is set: this test must run, not skip)"; \
    else                                                                                       \
      GTEST_SKIP() << message;                                                                 \
  } while (0)

// Skips the test, visibly, when ../shared/scenes is not available (fails where skips are forbidden).
#define TILESPLAT_REQUIRE_SHARED_SCENES()                                                       \
  do {                                                                                          \
    if (::tilesplat::testing::shared_scenes().empty())                                          \
      TILESPLAT_SKIP_OR_FAIL(                                                                   \
          "shared scenes not found: set TILESPLAT_SHARED_SCENES or -DTILESPLAT_SHARED_SCENES"); \
  } while (0)
