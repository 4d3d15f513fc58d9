#include "test_support.h"

#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/scene_in_parts.h"

namespace tilesplat::testing {

std::filesystem::path bundled_scene_dir() { return std::filesystem::path(TILESPLAT_SOURCE_DIR) / "scenes"; }
std::filesystem::path bundled_playbot() {
  return bundled_scene_dir() / "playbot_lod3" / "playbot_lod3_31000_sh2.ply";
}
std::filesystem::path bundled_playbot_cameras() {
  return bundled_scene_dir() / "playbot_lod3" / "playbot_lod3_31000_sh2.json";
}
std::filesystem::path bundled_sh3() {
  return bundled_scene_dir() / "playcanvas_test" / "playcanvas_test_64_sh3.ply";
}
std::filesystem::path bundled_sh3_cameras() {
  return bundled_scene_dir() / "playcanvas_test" / "playcanvas_test_64_sh3.json";
}

std::filesystem::path shared_scenes() {
  std::filesystem::path dir;
  if (const char* env = std::getenv("TILESPLAT_SHARED_SCENES"); env && *env)
    dir = env;
  else
    dir = TILESPLAT_SHARED_SCENES_DEFAULT;
  std::error_code ec;
  if (std::filesystem::is_directory(dir / "cameras", ec)) return dir;
  return {};
}

bool skips_forbidden() {
  const char* value = std::getenv("TILESPLAT_NO_SKIPS");
  return value && *value && std::string(value) != "0";
}

Camera axis_camera(int width, int height, double focal) {
  Camera camera;
  camera.width = width;
  camera.height = height;
  camera.fx = camera.fy = focal;
  camera.cx = width / 2.0;
  camera.cy = height / 2.0;
  return camera;
}

std::filesystem::path write_temp_file(const std::string& folder, const std::string& name, const std::string& bytes) {
  const std::filesystem::path path = temp_dir() / folder / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

GaussianScene with_sh_degree(const GaussianScene& scene, int degree) {
  GaussianScene truncated = scene;
  truncated.sh_degree = degree;
  truncated.sh.clear();
  const size_t have = size_t(scene.sh_coefficients()), kept = size_t((degree + 1) * (degree + 1));
  for (size_t i = 0; i < scene.size(); ++i)
    truncated.sh.insert(truncated.sh.end(), scene.sh.begin() + std::ptrdiff_t(i * have * 3),
                        scene.sh.begin() + std::ptrdiff_t((i * have + kept) * 3));
  return truncated;
}

void expect_read_in_parts_as_whole(const std::filesystem::path& path, const Camera& camera) {
  SCOPED_TRACE(path.filename().string() + " read part by part");
  LoadReport whole_report, parts_report;
  const GaussianScene whole = load_scene(path, {}, &whole_report);
  const SceneInParts in_parts = SceneInParts::open(path, {}, &parts_report);
  EXPECT_EQ(parts_report.format, whole_report.format);
  EXPECT_EQ(parts_report.gaussians_in_file, whole_report.gaussians_in_file);
  ASSERT_EQ(in_parts.size(), whole.size());
  ASSERT_EQ(in_parts.sh_degree(), whole.sh_degree);
  const GaussianScene loaded = in_parts.load();  // every part's Gaussians, decoded as a part decodes them
  ASSERT_EQ(loaded.size(), whole.size());
  EXPECT_EQ(loaded.positions, whole.positions);
  EXPECT_EQ(loaded.log_scales, whole.log_scales);
  EXPECT_EQ(loaded.rotations, whole.rotations);
  EXPECT_EQ(loaded.opacity_logits, whole.opacity_logits);
  EXPECT_EQ(loaded.sh, whole.sh);
  Renderer& renderer = validated_renderer();
  RenderSettings settings;
  settings.reuse_lists = false;
  renderer.set_scene(whole);
  const RenderImage frame = renderer.render(camera, settings);
  settings.memory_budget = 274 << 10;  // the 64x48 frame holds 0.26 MiB before any Gaussian: a few parts
  const RenderImage parts = renderer.render(in_parts, camera, settings);
  EXPECT_GE(renderer.last_frame_stats().scene_parts, 2);
  EXPECT_EQ(parts.rgba, frame.rgba);
  renderer.set_scene(whole);  // the renderer holds the last part
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

std::string glb_bytes(std::string json_text, std::string bin) {
  while (json_text.size() % 4) json_text += ' ';
  while (bin.size() % 4) bin += '\0';
  std::string out;
  const auto append = [&out](uint32_t value) {
    for (int shift = 0; shift < 32; shift += 8) out += static_cast<char>((value >> shift) & 0xff);
  };
  append(0x46546c67);  // "glTF"
  append(2);
  append(static_cast<uint32_t>(12 + 8 + json_text.size() + 8 + bin.size()));
  append(static_cast<uint32_t>(json_text.size()));
  append(0x4e4f534a);  // "JSON"
  out += json_text;
  append(static_cast<uint32_t>(bin.size()));
  append(0x004e4942);  // "BIN\0"
  out += bin;
  return out;
}

std::filesystem::path temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "tilesplat";
  for (char& c : name)
    if (c == '/') c = '_';
  auto dir = std::filesystem::temp_directory_path() / "tilesplat_tests" / name;
  std::filesystem::create_directories(dir);
  return dir;
}

Renderer& validated_renderer() {
  static std::unique_ptr<Renderer> renderer = [] {
    RendererOptions options;
    options.validation = true;
    return Renderer::create(options);
  }();
  return *renderer;
}

CutoffAwareDifference compare_allowing_cutoff_flips(const RenderImage& gpu, const RenderImage& reference) {
  if (gpu.splat_count.size() != gpu.pixels() || reference.splat_count.size() != reference.pixels())
    throw std::invalid_argument("compare_allowing_cutoff_flips: both images need splat counts");
  CutoffAwareDifference result;
  RenderImage masked = gpu;
  for (size_t i = 0; i < gpu.pixels() && i < reference.pixels(); ++i) {
    if (gpu.splat_count[i] == reference.splat_count[i]) continue;
    ++result.flipped;
    const uint32_t a = gpu.splat_count[i], b = reference.splat_count[i];
    result.flipped_splats = std::max(result.flipped_splats, a > b ? a - b : b - a);
    for (size_t c = 0; c < 4; ++c) {
      result.flipped_max_abs =
          std::max(result.flipped_max_abs, double(std::abs(gpu.rgba[4 * i + c] - reference.rgba[4 * i + c])));
      masked.rgba[4 * i + c] = reference.rgba[4 * i + c];
    }
  }
  result.agreeing = compare_images(masked, reference);
  return result;
}

void expect_matches_reference(const RenderImage& gpu, const RenderImage& reference, double max_abs,
                              const std::string& what) {
  const CutoffAwareDifference d = compare_allowing_cutoff_flips(gpu, reference);
  EXPECT_LE(d.agreeing.max_abs, max_abs) << what << ": worst pixel (" << d.agreeing.worst_x << ", "
                                         << d.agreeing.worst_y << ") channel " << d.agreeing.worst_channel;
  EXPECT_LE(d.agreeing.max_abs_alpha, max_abs) << what;
  EXPECT_LE(double(d.flipped), 1e-3 * double(gpu.pixels())) << what << ": pixels whose splat count differs";
  if (d.flipped > 0) {
    EXPECT_EQ(d.flipped_splats, 1u) << what << ": a cut-off decision flips one splat, not more";
    EXPECT_LT(d.flipped_max_abs, 1.0 / 64) << what;
  }
}

void expect_composite_layouts_identical(const GaussianScene& scene, const Camera& camera,
                                        const RenderSettings& settings) {
  std::vector<RenderImage> images;
  struct Layout {
    const char* pixels;         // TILESPLAT_COMPOSITE_PIXELS
    const char* texel_buffers;  // TILESPLAT_TEXEL_BUFFERS
  };
  for (const Layout& layout : {Layout{"1", "0"}, Layout{"4", "1"}, Layout{"16", "0"}, Layout{"16", "1"}}) {
    ::setenv("TILESPLAT_COMPOSITE_PIXELS", layout.pixels, 1);
    ::setenv("TILESPLAT_TEXEL_BUFFERS", layout.texel_buffers, 1);
    RendererOptions options;
    options.validation = true;
    auto renderer = Renderer::create(options);
    ::unsetenv("TILESPLAT_COMPOSITE_PIXELS");
    ::unsetenv("TILESPLAT_TEXEL_BUFFERS");
    images.push_back(renderer->render(scene, camera, settings));  // in parts under settings.memory_budget
    EXPECT_EQ(renderer->validation_messages(), 0u)
        << layout.pixels << " pixels per invocation, texel buffers " << layout.texel_buffers;
  }
  for (size_t k = 1; k < images.size(); ++k) {
    EXPECT_EQ(images[k].rgba, images[0].rgba) << "layout " << k;
    EXPECT_EQ(images[k].depth, images[0].depth) << "layout " << k;
    EXPECT_EQ(images[k].splat_count, images[0].splat_count) << "layout " << k;
  }
}

DecodedPng read_png_rgb(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) throw std::runtime_error(png.message);
  png.format = PNG_FORMAT_RGB;
  DecodedPng decoded;
  decoded.width = png.width;
  decoded.height = png.height;
  decoded.rgb.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, decoded.rgb.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw std::runtime_error(message);
  }
  return decoded;
}

void replay_fuzz_regressions(const std::string& reader, size_t at_least,
                             int (*harness)(const uint8_t*, size_t)) {
  const std::filesystem::path dir =
      std::filesystem::path(TILESPLAT_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / reader;
  std::vector<std::filesystem::path> inputs;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file()) inputs.push_back(entry.path());
  std::sort(inputs.begin(), inputs.end());
  ASSERT_GE(inputs.size(), at_least) << "the " << reader << " regressions in " << dir << " are missing";
  for (const std::filesystem::path& input : inputs) {
    SCOPED_TRACE(input.filename().string());
    std::ifstream file(input, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(file)),
                                     std::istreambuf_iterator<char>());
    ASSERT_FALSE(bytes.empty());
    EXPECT_EQ(harness(bytes.data(), bytes.size()), 0);
  }
}

void expect_identical_scenes(const GaussianScene& actual, const GaussianScene& expected, bool rotations) {
  EXPECT_EQ(actual.sh_degree, expected.sh_degree);
  EXPECT_EQ(actual.positions, expected.positions);
  EXPECT_EQ(actual.log_scales, expected.log_scales);
  if (rotations) {
    EXPECT_EQ(actual.rotations, expected.rotations);
  }
  EXPECT_EQ(actual.opacity_logits, expected.opacity_logits);
  EXPECT_EQ(actual.sh, expected.sh);
  EXPECT_EQ(actual.normals, expected.normals);
}

float max_abs_difference(const std::vector<float>& a, const std::vector<float>& b) {
  float most = 0;
  for (size_t i = 0; i < a.size(); ++i) most = std::max(most, std::abs(a[i] - b[i]));
  return most;
}

void expect_scene_error(const std::filesystem::path& path, std::initializer_list<std::string> phrases) {
  SCOPED_TRACE(path.filename().string());
  try {
    load_scene(path);
    ADD_FAILURE() << "loaded without an error";
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_TRUE(message.starts_with(path.string())) << message;
    for (const std::string& phrase : phrases) EXPECT_NE(message.find(phrase), std::string::npos) << message;
  }
}

}  // namespace tilesplat::testing
