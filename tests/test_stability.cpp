// The stability suite: generated hard cases (docs/rendering-math.md, section 5) that each have one defined
// outcome. Every case is a scene built in memory from raw parameters, a camera and an expectation:
//  - render: every sort strategy renders without an exception or a validation message, every output
//    value is finite, the image is within the case's bound of the float64 reference, the exact
//    strategies agree bit for bit, and rendering again gives the same bits;
//  - culled: additionally, the scene renders bit-identically to the same scene without one splat
//    (a Gaussian with a value the renderer cannot use, or one the near plane culls);
//  - render or throw: either all of the above, or an exception naming the cause;
//  - throw: render() throws an exception naming the cause, and the renderer still renders a normal
//    scene correctly afterwards.
// Everything is seeded: the suite renders the same images on every run. Each case prints what it
// measured ("[ measure  ]" lines), which is what the bounds beside the cases were set from.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// ---------------------------------------------------------------------------------------------
// Scenes

// One Gaussian in raw (trainer) parameters.
struct SplatSpec {
  std::array<float, 3> position = {0.1f, -0.05f, 3.0f};
  std::array<float, 3> log_scale = {-1.8f, -1.5f, -2.0f};
  std::array<float, 4> rotation = {0.9f, 0.2f, -0.3f, 0.25f};  // w x y z, not normalized
  float opacity_logit = 3.0f;
  std::array<float, 3> dc = {1.5f, -0.5f, 0.8f};
  float rest = 0.3f;  // every coefficient above the DC one, every channel (scenes of degree > 0)
  // One coefficient above the DC one (1 to 15) whose green channel is `odd_value` instead; 0 = none.
  int odd_coefficient = 0;
  float odd_value = 0;
};

void add_splat(GaussianScene& scene, const SplatSpec& s) {
  scene.positions.insert(scene.positions.end(), s.position.begin(), s.position.end());
  scene.log_scales.insert(scene.log_scales.end(), s.log_scale.begin(), s.log_scale.end());
  scene.rotations.insert(scene.rotations.end(), s.rotation.begin(), s.rotation.end());
  scene.opacity_logits.push_back(s.opacity_logit);
  scene.sh.insert(scene.sh.end(), s.dc.begin(), s.dc.end());
  const size_t first_rest = scene.sh.size();
  scene.sh.insert(scene.sh.end(), size_t(3 * (scene.sh_coefficients() - 1)), s.rest);
  if (s.odd_coefficient > 0) scene.sh.at(first_rest + size_t(3 * (s.odd_coefficient - 1) + 1)) = s.odd_value;
}

// Gaussian i of `from`, appended to `to` (same SH degree).
void copy_gaussian(const GaussianScene& from, size_t i, GaussianScene& to) {
  auto copy = [i](const std::vector<float>& src, std::vector<float>& dst, size_t per) {
    dst.insert(dst.end(), src.begin() + std::ptrdiff_t(i * per), src.begin() + std::ptrdiff_t((i + 1) * per));
  };
  copy(from.positions, to.positions, 3);
  copy(from.log_scales, to.log_scales, 3);
  copy(from.rotations, to.rotations, 4);
  copy(from.opacity_logits, to.opacity_logits, 1);
  copy(from.sh, to.sh, size_t(3 * from.sh_coefficients()));
}

// `base` with one more Gaussian inserted at `index` (the rest keep their relative order).
GaussianScene with_splat(const GaussianScene& base, size_t index, const SplatSpec& spec) {
  GaussianScene scene;
  scene.sh_degree = base.sh_degree;
  for (size_t i = 0; i <= base.size(); ++i) {
    if (i == index) add_splat(scene, spec);
    if (i < base.size()) copy_gaussian(base, i, scene);
  }
  return scene;
}

// The first `count` Gaussians of a scene.
GaussianScene first_splats(const GaussianScene& base, size_t count) {
  GaussianScene scene;
  scene.sh_degree = base.sh_degree;
  for (size_t i = 0; i < std::min(count, base.size()); ++i) copy_gaussian(base, i, scene);
  return scene;
}

// Uniform floats from the standard's fully specified mt19937 (std::uniform_real_distribution is
// implementation-defined: another standard library would generate other scenes).
class Random {
 public:
  explicit Random(uint32_t seed) : engine_(seed) {}
  float uniform(float lo, float hi) { return lo + (hi - lo) * float(engine_() >> 8) * 0x1p-24f; }

 private:
  std::mt19937 engine_;
};

// Where and how big the Gaussians of a random cloud are. The default fills the view of
// axis_camera() at a 50 degree vertical field of view with splats a few pixels across at 64x48.
struct CloudShape {
  std::array<float, 3> lo = {-1.2f, -0.9f, 2.5f};
  std::array<float, 3> hi = {1.2f, 0.9f, 4.0f};
  float log_scale_lo = -3.2f, log_scale_hi = -2.0f;
  float logit_lo = -1.0f, logit_hi = 3.0f;
  int sh_degree = 0;
};

GaussianScene random_cloud(size_t count, uint32_t seed, const CloudShape& shape = {}) {
  Random random(seed);
  GaussianScene scene;
  scene.sh_degree = shape.sh_degree;
  for (size_t i = 0; i < count; ++i) {
    for (size_t a = 0; a < 3; ++a) scene.positions.push_back(random.uniform(shape.lo[a], shape.hi[a]));
    for (size_t a = 0; a < 3; ++a) scene.log_scales.push_back(random.uniform(shape.log_scale_lo, shape.log_scale_hi));
    for (size_t a = 0; a < 4; ++a) scene.rotations.push_back(random.uniform(-1.0f, 1.0f));
    scene.opacity_logits.push_back(random.uniform(shape.logit_lo, shape.logit_hi));
    for (int c = 0; c < 3; ++c) scene.sh.push_back(random.uniform(-1.5f, 1.5f));
    for (int c = 3; c < 3 * scene.sh_coefficients(); ++c) scene.sh.push_back(random.uniform(-0.25f, 0.25f));
  }
  return scene;
}

// The cloud most cases put their special splat into.
GaussianScene base_cloud(int sh_degree = 0) {
  CloudShape shape;
  shape.sh_degree = sh_degree;
  return random_cloud(60, 20240601, shape);
}

// n splats that each cover the whole screen of axis_camera() with alpha ~0.8 everywhere (scale
// 50 at depth 5: sigma is ten times the image), all at exactly the same depth, colours by index. An
// (x, y) jitter keeps them distinct. Equal depths blend in index order, so every pixel is decided
// by the first six splats (T = 0.2^6 < 1e-4 stops it), whatever n is.
GaussianScene full_screen_splats(size_t count) {
  Random random(77);
  GaussianScene scene;
  for (size_t i = 0; i < count; ++i) {
    SplatSpec s;
    s.position = {random.uniform(-0.1f, 0.1f), random.uniform(-0.1f, 0.1f), 5.0f};
    s.log_scale = {3.9f, 3.9f, 3.9f};
    s.rotation = {1, 0, 0, 0};
    s.opacity_logit = 1.3863f;  // 0.8: T falls to 3.2e-4 after 5 splats, 6.4e-5 after 6: far from 1e-4
    s.dc = {random.uniform(-1.5f, 1.5f), random.uniform(-1.5f, 1.5f), random.uniform(-1.5f, 1.5f)};
    add_splat(scene, s);
  }
  return scene;
}

// ---------------------------------------------------------------------------------------------
// Cameras

double focal_for_fov(int pixels, double fov_deg) {
  return pixels / (2.0 * std::tan(fov_deg * std::numbers::pi / 360.0));
}

// At the origin looking down +z with the identity rotation, so that view z is world z exactly
// (the near-plane cases rely on it); square pixels, principal point at the centre.
Camera axis_camera(int width, int height, double vertical_fov_deg = 50) {
  return testing::axis_camera(width, height, focal_for_fov(height, vertical_fov_deg));
}

// ---------------------------------------------------------------------------------------------
// Expectations

// An unset field is not checked (it is still measured and printed).
struct Bound {
  std::optional<double> min_psnr_db;    // RGB, peak 1
  std::optional<double> max_abs;        // RGB
  std::optional<double> max_abs_alpha;  // A
  std::optional<double> max_rel;        // RGB, |a - b| / max(1, |b|): for colours far beyond [0, 1]
};

// The exact strategies on ordinary cases: float32 blending of float64-correct splats. Measured (lavapipe)
// 116 to 150 dB, max abs 2.9e-5 and alpha 3.2e-5 at worst (the needles); the bound leaves 16 dB and
// a factor 7. A splat that lands within float32 rounding of the 1/255 alpha cut-off at some pixel
// changes that pixel by up to 1/255 (see kOneCutoffFlip): none of these small images has one.
const Bound kTight = {100.0, 2e-4, 2e-4, std::nullopt};
// The 8192x8192 image has 17 pixels (of 67M) where a splat's alpha is within 6e-8 (relative) of the
// 1/255 cut-off, below float32 resolution: the GPU blends it, the reference skips it. Measured
// 121 dB, max abs 3.55e-3, alpha 3.92e-3 (= 1/255). The bound allows one such flip at a pixel.
const Bound kOneCutoffFlip = {100.0, 4.5e-3, 4.5e-3, std::nullopt};
// Needles (aspect 1e3 to 1e9) at 256x192. Across the needle the conic is ~3 and along it ~1e-4, so
// the composite's float32 power, a sum of terms of 1e5 that cancel near the needle's axis, loses
// ~1e-2 in the exponent 100 pixels from the mean. Measured 100.4 to 102.2 dB, max abs 6.3e-4,
// alpha 6.8e-4 (20 times the other cases); the bound leaves 10 dB and a factor 3.
const Bound kNeedle = {90.0, 2e-3, 2e-3, std::nullopt};
// The small object 1e5 from the origin, seen from 0.5 units: camera-relative float64 projection keeps
// it as accurate as any other. Measured 145 dB, max abs 4.8e-7, alpha 6e-7 (float32 positions alone
// would be off by 1/128 unit there, a third of the view). A factor 20 above what was measured.
const Bound kFarFromOrigin = {120.0, 1e-5, 1e-5, std::nullopt};
// cpu-radix16 sorts by depths quantized to 16 bits over the visible range: splats closer than one
// quantum blend in index order. Measured: identical to the exact strategies except Position_Far1e7
// (range 2.5 to 1e7: the whole cloud falls in one quantum), 37.4 dB, max abs 0.25, alpha 4e-7.
// Alpha barely depends on the order (only through the T < 1e-4 stop).
const Bound kApprox = {30.0, std::nullopt, 1e-3, std::nullopt};
// Colours far beyond [0, 1] (SH 1e20, 1e30) are compared relative to their size; alpha keeps its
// absolute bound. Measured rel 2.9e-6, alpha 3.6e-7 (every strategy).
const Bound kRelative = {std::nullopt, std::nullopt, 2e-4, 2e-5};
const Bound kRelativeApprox = {std::nullopt, std::nullopt, 1e-3, 1e-2};

enum class Expect {
  kRender,         // must render within the bound
  kRenderOrThrow,  // may instead throw naming `error` (never a wrong image)
  kThrow,          // must throw naming `error`
};

struct StabilityCase {
  std::string name;
  std::function<GaussianScene()> scene;
  std::function<Camera()> camera;
  Expect expect = Expect::kRender;
  Bound bound = kTight;          // the exact strategies against the reference
  Bound approx_bound = kApprox;  // the approximate strategy (cpu-radix16) against the reference
  // Culled cases: the scene without the splat that must not be drawn. The GPU image must equal this
  // scene's bit for bit, and the reference's image of it must be within `bound`.
  std::function<GaussianScene()> culled_equivalent;
  // A cheaper scene whose reference image is provably the same (see full_screen_splats).
  std::function<GaussianScene()> reference_scene;
  std::string error;  // kThrow, kRenderOrThrow: a substring of what() that names the cause
  // kThrow: render_reference must reject the camera too (naming `error`).
  bool reference_rejects = false;
  // Only the default strategy (for the cases too big to render six times).
  bool default_strategy_only = false;
  bool depth_and_counts = true;
  std::array<float, 3> background = {0, 0, 0};
};

void PrintTo(const StabilityCase& c, std::ostream* os) { *os << c.name; }

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

size_t non_finite_values(const RenderImage& image) {
  size_t bad = 0;
  for (float v : image.rgba) bad += !std::isfinite(v);
  for (float v : image.depth) bad += !std::isfinite(v);
  return bad;
}

// Bit-for-bit equality of colour, depth and splat counts, with a short message instead of gtest's
// print of two whole vectors.
template <typename T>
size_t bits_differ(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return std::max(a.size(), b.size()) + 1;
  if (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0) return 0;
  size_t differ = 0;
  for (size_t i = 0; i < a.size(); ++i) differ += std::memcmp(&a[i], &b[i], sizeof(T)) != 0;
  return differ;
}
void expect_identical(const RenderImage& a, const RenderImage& b, const std::string& what) {
  ASSERT_EQ(a.width, b.width) << what;
  ASSERT_EQ(a.height, b.height) << what;
  EXPECT_EQ(bits_differ(a.rgba, b.rgba), 0u) << what << ": rgba values differ";
  EXPECT_EQ(bits_differ(a.depth, b.depth), 0u) << what << ": depth values differ";
  EXPECT_EQ(bits_differ(a.splat_count, b.splat_count), 0u) << what << ": splat counts differ";
}

double max_relative_error(const RenderImage& a, const RenderImage& b) {
  double worst = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    const double x = a.rgba[i], y = b.rgba[i];
    const double rel = std::fabs(x - y) / std::max(1.0, std::fabs(y));
    if (std::isnan(rel)) return rel;
    worst = std::max(worst, rel);
  }
  return worst;
}

// Fraction of pixels something was blended into: a case whose special splat draws nothing would
// test nothing, so every case prints it.
double coverage(const RenderImage& image) {
  if (image.pixels() == 0) return 0;
  size_t covered = 0;
  for (size_t i = 0; i < image.pixels(); ++i) covered += image.rgba[4 * i + 3] > 0.01f;
  return double(covered) / double(image.pixels());
}

void expect_within(const RenderImage& image, const RenderImage& reference, const Bound& bound,
                   const std::string& what) {
  const ImageDifference d = compare_images(image, reference);
  const double rel = max_relative_error(image, reference);
  std::printf("[ measure  ] %-58s PSNR %7.2f dB  max abs %.2e at (%d, %d)  alpha %.2e  rel %.2e\n", what.c_str(),
              d.psnr_db, d.max_abs, d.worst_x, d.worst_y, d.max_abs_alpha, rel);
  if (bound.min_psnr_db) {
    EXPECT_GE(d.psnr_db, *bound.min_psnr_db) << what;
  }
  if (bound.max_abs) {
    EXPECT_LE(d.max_abs, *bound.max_abs) << what << ": worst pixel (" << d.worst_x << ", " << d.worst_y << ") channel "
                                         << d.worst_channel;
  }
  if (bound.max_abs_alpha) {
    EXPECT_LE(d.max_abs_alpha, *bound.max_abs_alpha) << what;
  }
  if (bound.max_rel) {
    EXPECT_LE(rel, *bound.max_rel) << what;
  }
}

// Renders and checks what every successful render must satisfy.
RenderImage checked_render(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                           const std::string& what) {
  const uint64_t messages = renderer.validation_messages();
  const auto start = std::chrono::steady_clock::now();
  RenderImage image = renderer.render(camera, settings);
  std::printf("[ measure  ] %-58s rendered in %.0f ms\n", what.c_str(), milliseconds_since(start));
  EXPECT_EQ(renderer.validation_messages(), messages) << what << ": validation messages";
  EXPECT_EQ(image.width, camera.width) << what;
  EXPECT_EQ(image.height, camera.height) << what;
  EXPECT_EQ(non_finite_values(image), 0u) << what << ": non-finite output values";
  return image;
}

// After an error the renderer must still work: a normal scene renders as the reference does.
void expect_renderer_still_works(Renderer& renderer) {
  const GaussianScene scene = base_cloud();
  const Camera camera = axis_camera(64, 48);
  renderer.set_scene(scene);
  RenderImage image = checked_render(renderer, camera, {}, "normal scene after the error");
  expect_within(image, render_reference(scene, camera), kTight, "normal scene after the error");
}

std::vector<std::string> strategies_of(const StabilityCase& c) {
  std::vector<std::string> all = sort_strategies();
  if (c.default_strategy_only) all.resize(1);
  return all;
}

void run_render_case(const StabilityCase& c) {
  Renderer& renderer = testing::validated_renderer();
  const uint64_t messages = renderer.validation_messages();
  const GaussianScene scene = c.scene();
  const Camera camera = c.camera();
  RenderSettings settings;
  settings.background = c.background;
  settings.depth = settings.splat_count = c.depth_and_counts;

  // The reference is made only once something rendered: a render-or-throw case may be far too big.
  std::optional<RenderImage> reference;
  auto get_reference = [&]() -> const RenderImage& {
    if (!reference) {
      const auto start = std::chrono::steady_clock::now();
      reference = render_reference(c.reference_scene ? c.reference_scene() : scene, camera, settings);
      EXPECT_EQ(non_finite_values(*reference), 0u) << "the reference has non-finite values";
      std::printf("[ measure  ] %-58s coverage %.3f of %dx%d pixels, reference %.0f ms\n", c.name.c_str(),
                  coverage(*reference), camera.width, camera.height, milliseconds_since(start));
    }
    return *reference;
  };

  renderer.set_scene(scene);
  const std::vector<std::string> strategies = strategies_of(c);
  std::vector<std::optional<RenderImage>> images;  // per strategy, empty where it threw
  images.reserve(strategies.size());               // first_exact points into it
  const RenderImage* first_exact = nullptr;
  std::string first_exact_name;
  for (const std::string& strategy : strategies) {
    const std::string what = c.name + " [" + strategy + "]";
    settings.sort = strategy;
    images.emplace_back();
    const auto start = std::chrono::steady_clock::now();
    try {
      images.back() = checked_render(renderer, camera, settings, what);
    } catch (const std::exception& e) {
      if (c.expect == Expect::kRenderOrThrow && contains(e.what(), c.error)) {
        std::printf("[ measure  ] %-58s threw (allowed) after %.0f ms: %s\n", what.c_str(), milliseconds_since(start),
                    e.what());
        continue;
      }
      ADD_FAILURE() << what << " threw: " << e.what();
      continue;
    }
    const RenderImage& image = *images.back();
    if (sort_strategy_is_exact(strategy)) {
      expect_within(image, get_reference(), c.bound, what);
      if (first_exact) {
        expect_identical(image, *first_exact, what + " vs " + first_exact_name);
      } else {
        first_exact = &image;
        first_exact_name = strategy;
      }
    } else {
      expect_within(image, get_reference(), c.approx_bound, what);
      expect_identical(checked_render(renderer, camera, settings, what), image, what + " rendered twice");
    }
  }
  if (std::any_of(images.begin(), images.end(), [](const auto& image) { return !image; }))
    expect_renderer_still_works(renderer);

  // The default strategy again: the same bits.
  if (images.front()) {
    settings.sort = strategies.front();
    expect_identical(checked_render(renderer, camera, settings, c.name + " again"), *images.front(),
                     c.name + " [" + strategies.front() + "] rendered twice");
  }

  if (c.culled_equivalent) {
    const GaussianScene without = c.culled_equivalent();
    const RenderImage reference_without = render_reference(without, camera, settings);
    if (reference) expect_within(*reference, reference_without, c.bound, c.name + " reference vs without the splat");
    renderer.set_scene(without);
    for (size_t s = 0; s < strategies.size(); ++s) {
      if (!images[s]) continue;
      settings.sort = strategies[s];
      const std::string what = c.name + " [" + strategies[s] + "] vs without the splat";
      expect_identical(*images[s], checked_render(renderer, camera, settings, what), what);
    }
  }
  EXPECT_EQ(renderer.validation_messages(), messages) << c.name << ": validation messages";
}

void expect_throw_naming(const std::function<void()>& call, const std::string& part, const std::string& what) {
  try {
    call();
    ADD_FAILURE() << what << ": expected an exception naming \"" << part << "\", got none";
  } catch (const std::exception& e) {
    std::printf("[ measure  ] %-58s threw: %s\n", what.c_str(), e.what());
    EXPECT_TRUE(contains(e.what(), part)) << what << ": the message does not name \"" << part << "\": " << e.what();
  }
}

void run_error_case(const StabilityCase& c) {
  Renderer& renderer = testing::validated_renderer();
  const uint64_t messages = renderer.validation_messages();
  const GaussianScene scene = c.scene();
  const Camera camera = c.camera();
  renderer.set_scene(scene);
  for (const std::string& strategy : strategies_of(c)) {
    RenderSettings settings;
    settings.sort = strategy;
    expect_throw_naming([&] { renderer.render(camera, settings); }, c.error, c.name + " [" + strategy + "]");
  }
  if (c.reference_rejects)
    expect_throw_naming([&] { render_reference(scene, camera); }, c.error, c.name + " [reference]");
  expect_renderer_still_works(renderer);
  EXPECT_EQ(renderer.validation_messages(), messages) << c.name << ": validation messages";
}

// ---------------------------------------------------------------------------------------------
// The cases

// A case whose scene is the base cloud plus one special splat in the middle of it.
StabilityCase splat_case(std::string name, SplatSpec spec, int sh_degree = 0) {
  StabilityCase c;
  c.name = std::move(name);
  c.scene = [spec, sh_degree] { return with_splat(base_cloud(sh_degree), 30, spec); };
  c.camera = [] { return axis_camera(64, 48); };
  return c;
}

// The same, with colours far beyond [0, 1].
StabilityCase huge_colour_case(std::string name, SplatSpec spec, int sh_degree) {
  StabilityCase c = splat_case(std::move(name), spec, sh_degree);
  c.bound = kRelative;
  c.approx_bound = kRelativeApprox;
  return c;
}

// The same, for a splat that must be culled: the image is the cloud's alone.
StabilityCase culled_splat_case(std::string name, SplatSpec spec, int sh_degree = 0) {
  StabilityCase c = splat_case(std::move(name), spec, sh_degree);
  c.culled_equivalent = [sh_degree] { return base_cloud(sh_degree); };
  return c;
}

SplatSpec with_log_scales(float x, float y, float z) {
  SplatSpec s;
  s.log_scale = {x, y, z};
  return s;
}

// A needle: one axis `aspect` times the other two, rotated 30 degrees about the view axis so that it
// crosses the tile grid diagonally. At 256x192 its long axis has a sigma of 137 pixels: it crosses the
// whole image, through about 30 of the 192 tiles.
StabilityCase needle_case(std::string name, double aspect) {
  SplatSpec s;
  s.position = {0.0f, 0.0f, 3.0f};
  const float thin = float(std::log(2.0 / aspect));
  s.log_scale = {float(std::log(2.0)), thin, thin};
  s.rotation = {float(std::cos(std::numbers::pi / 12)), 0.0f, 0.0f, float(std::sin(std::numbers::pi / 12))};
  StabilityCase c = splat_case(std::move(name), s);
  c.camera = [] { return axis_camera(256, 192); };
  c.bound = kNeedle;
  return c;
}

std::vector<StabilityCase> scale_cases() {
  return {
      splat_case("Scale_LogMinus100", with_log_scales(-100, -100, -100)),  // exp underflows to 0 in float
      splat_case("Scale_1em30", with_log_scales(-69.0776f, -69.0776f, -69.0776f)),  // ln(1e-30)
      // A splat of scale 1e6 in front of the camera (which is inside it): it covers the screen.
      splat_case("Scale_1e6", with_log_scales(13.8155f, 13.8155f, 13.8155f)),
      needle_case("Needle_Aspect1e3", 1e3),
      needle_case("Needle_Aspect1e6", 1e6),
      needle_case("Needle_Aspect1e9", 1e9),
      splat_case("Scale_ZeroAllAxes", with_log_scales(-1000, -1000, -1000)),  // exp is 0 in float and double
      splat_case("Scale_LogMinusInfAllAxes", with_log_scales(-kInf, -kInf, -kInf)),  // scale 0 exactly
  };
}

SplatSpec with_rotation(float w, float x, float y, float z) {
  SplatSpec s;
  s.rotation = {w, x, y, z};
  return s;
}

std::vector<StabilityCase> rotation_cases() {
  return {
      splat_case("Quat_Zero", with_rotation(0, 0, 0, 0)),  // the identity
      splat_case("Quat_Denormal", with_rotation(1e-40f, 1e-40f, 1e-40f, 1e-40f)),  // the zero quaternion
      splat_case("Quat_Unnormalized1e6", with_rotation(0.5e6f, 0.5e6f, -0.5e6f, 0.5e6f)),
      culled_splat_case("Quat_NaNComponent", with_rotation(0.9f, kNaN, -0.3f, 0.25f)),
  };
}

SplatSpec with_opacity(float logit) {
  SplatSpec s;
  s.opacity_logit = logit;
  return s;
}
SplatSpec with_dc(float r, float g, float b, float rest = 0.3f) {
  SplatSpec s;
  s.dc = {r, g, b};
  s.rest = rest;
  return s;
}

std::vector<StabilityCase> opacity_colour_cases() {
  return {
      splat_case("Opacity_LogitPlus100", with_opacity(100)),
      splat_case("Opacity_LogitMinus100", with_opacity(-100)),
      splat_case("Opacity_LogitPlusInf", with_opacity(kInf)),
      splat_case("Opacity_LogitMinusInf", with_opacity(-kInf)),
      huge_colour_case("Colour_Dc1e30", with_dc(1e30f, 1e30f, 1e30f), 0),
      huge_colour_case("Colour_Sh3All1e20", with_dc(1e20f, 1e20f, 1e20f, 1e20f), 3),
      splat_case("Colour_Negative", with_dc(-10.0f, 1.0f, -3.0f, -0.5f), 3),  // R and B clamp to 0
  };
}

SplatSpec at(float x, float y, float z, float log_scale = -3.0f) {
  SplatSpec s;
  s.position = {x, y, z};
  s.log_scale = {log_scale, log_scale, log_scale};
  return s;
}

// 2000 splats of scale ~1e-3 in a 0.1 cube centred at (1e5, 1e5, 1e5), seen from 0.5 units away.
// Float positions there are 1/128 apart, so many splats coincide exactly (ties in index order).
constexpr double kFar = 1e5;
GaussianScene far_object() {
  CloudShape shape;
  shape.lo = {float(kFar - 0.05), float(kFar - 0.05), float(kFar - 0.05)};
  shape.hi = {float(kFar + 0.05), float(kFar + 0.05), float(kFar + 0.05)};
  shape.log_scale_lo = -7.4f;  // ln(6e-4)
  shape.log_scale_hi = -6.4f;  // ln(1.7e-3)
  shape.sh_degree = 1;
  return random_cloud(2000, 99, shape);
}
Camera far_object_camera() {
  // From the direction (0.48, -0.36, -0.8) (unit length), 0.5 units away.
  return look_at_camera({kFar + 0.24, kFar - 0.18, kFar - 0.4}, {kFar, kFar, kFar}, {0, -1, 0}, 96, 64, 15);
}

std::vector<StabilityCase> position_cases() {
  const float near = 0.2f;
  std::vector<StabilityCase> cases = {
      culled_splat_case("Position_AtCameraCentre", at(0, 0, 0)),
      // 0.2f is 0.2000000030 > 0.2: in front of the near plane (the cull is z <= 0.2 in double).
      splat_case("Position_NearPlaneFloat", at(0, 0, near)),
      culled_splat_case("Position_NearPlaneUlpBelow", at(0, 0, std::nextafter(near, 0.0f))),  // 0.19999999
      splat_case("Position_NearPlaneUlpAbove", at(0, 0, std::nextafter(near, 1.0f))),
      culled_splat_case("Position_BehindCamera", at(0.1f, 0.1f, -3.0f, -1.0f)),
      // 1e7 along the view axis with a scale of 2e6: a sigma of about 10 pixels at 64x48.
      splat_case("Position_Far1e7", at(0, 0, 1e7f, 14.5087f)),
  };
  StabilityCase far;
  far.name = "Position_SmallObjectFarFromOrigin";
  far.scene = far_object;
  far.camera = far_object_camera;
  far.bound = kFarFromOrigin;
  cases.push_back(far);
  return cases;
}

// NaN and +-Inf in every attribute, one at a time, in a 200-splat SH degree 3 cloud.
struct Attribute {
  const char* name;
  std::function<void(SplatSpec&, float)> set;
};

std::vector<StabilityCase> non_finite_cases() {
  const std::vector<Attribute> attributes = {
      {"X", [](SplatSpec& s, float v) { s.position[0] = v; }},
      {"Y", [](SplatSpec& s, float v) { s.position[1] = v; }},
      {"Z", [](SplatSpec& s, float v) { s.position[2] = v; }},
      {"LogScale0", [](SplatSpec& s, float v) { s.log_scale[0] = v; }},
      {"LogScale1", [](SplatSpec& s, float v) { s.log_scale[1] = v; }},
      {"LogScale2", [](SplatSpec& s, float v) { s.log_scale[2] = v; }},
      {"QuatW", [](SplatSpec& s, float v) { s.rotation[0] = v; }},
      {"QuatX", [](SplatSpec& s, float v) { s.rotation[1] = v; }},
      {"QuatY", [](SplatSpec& s, float v) { s.rotation[2] = v; }},
      {"QuatZ", [](SplatSpec& s, float v) { s.rotation[3] = v; }},
      {"Opacity", [](SplatSpec& s, float v) { s.opacity_logit = v; }},
      {"ShDc", [](SplatSpec& s, float v) { s.dc[1] = v; }},
      // Coefficient 12 (degree 3, 0.37 z (2z^2 - 3x^2 - 3y^2), about 0.75 in this splat's direction).
      {"ShRest", [](SplatSpec& s, float v) {
         s.odd_coefficient = 12;
         s.odd_value = v;
       }},
  };
  const std::vector<std::pair<const char*, float>> values = {{"NaN", kNaN}, {"PosInf", kInf}, {"NegInf", -kInf}};
  auto base = [] {
    CloudShape shape;
    shape.sh_degree = 3;
    return random_cloud(200, 31337, shape);
  };
  std::vector<StabilityCase> cases;
  for (const Attribute& attribute : attributes)
    for (const auto& [value_name, value] : values) {
      SplatSpec spec;
      attribute.set(spec, value);
      StabilityCase c;
      c.name = std::string("NonFinite_") + attribute.name + "_" + value_name;
      c.scene = [base, spec] { return with_splat(base(), 100, spec); };
      c.camera = [] { return axis_camera(64, 48); };
      // Legitimate values, not errors: opacity logits +-inf are opacities 1 and 0, a log scale of -inf
      // is a scale of 0. Those are compared with the reference only; everything else is culled.
      const bool legitimate = (std::string(attribute.name) == "Opacity" && std::isinf(value)) ||
                              (contains(attribute.name, "LogScale") && value == -kInf);
      if (!legitimate) c.culled_equivalent = base;
      cases.push_back(c);
    }
  return cases;
}

std::vector<StabilityCase> crowd_cases() {
  std::vector<StabilityCase> cases;
  {
    StabilityCase c;
    c.name = "Crowd_100kAtOneDepth";  // equal depths blend in Gaussian index order, every strategy alike
    c.scene = [] {
      CloudShape shape;
      shape.lo[2] = shape.hi[2] = 3.0f;
      shape.log_scale_lo = -4.0f;
      shape.log_scale_hi = -3.0f;
      return random_cloud(100'000, 4242, shape);
    };
    c.camera = [] { return axis_camera(64, 48); };
    cases.push_back(c);
  }
  {
    StabilityCase c;
    c.name = "Crowd_OneSplatCoversScreen";
    c.scene = [] {
      GaussianScene scene;
      add_splat(scene, at(0, 0, 3.0f, 0.5f));  // scale 1.6 at depth 3: sigma 28 pixels, radius 85
      return scene;
    };
    c.camera = [] { return axis_camera(64, 48); };
    cases.push_back(c);
  }
  {
    StabilityCase c;
    c.name = "Crowd_100kCoverScreen_64x48";
    c.scene = [] { return full_screen_splats(100'000); };
    c.camera = [] { return axis_camera(64, 48); };
    cases.push_back(c);
  }
  // 100k x 21600 tiles = 2.16e9 pairs > 2^31; 100k x 65536 tiles = 6.6e9 > 2^32. Either rendered
  // right (the reference of the first 64 splats is the same image: see full_screen_splats) or refused
  // naming the tile intersections, never a wrapped count's wrong image.
  for (auto [width, height] : {std::pair{2560, 2160}, std::pair{4096, 4096}}) {
    StabilityCase c;
    c.name = "Crowd_100kCoverScreen_" + std::to_string(width) + "x" + std::to_string(height);
    c.scene = [] { return full_screen_splats(100'000); };
    c.reference_scene = [] { return first_splats(full_screen_splats(100'000), 64); };
    c.camera = [width, height] { return axis_camera(width, height); };
    c.expect = Expect::kRenderOrThrow;
    c.error = "tile intersections";
    cases.push_back(c);
  }
  {
    StabilityCase c;
    c.name = "Crowd_EmptyScene";
    c.scene = [] { return GaussianScene{}; };
    c.camera = [] { return axis_camera(64, 48); };
    c.background = {0.25f, 0.5f, 0.75f};
    cases.push_back(c);
  }
  {
    StabilityCase c;
    c.name = "Crowd_AllBehindCamera";
    c.scene = [] {
      CloudShape shape;
      shape.lo[2] = -4.0f;
      shape.hi[2] = -0.1f;
      return random_cloud(500, 5, shape);
    };
    c.camera = [] { return axis_camera(64, 48); };
    c.background = {0.25f, 0.5f, 0.75f};
    cases.push_back(c);
  }
  return cases;
}

std::vector<StabilityCase> image_size_cases() {
  std::vector<StabilityCase> cases;
  auto sized = [](std::string name, int width, int height, double vertical_fov = 50) {
    StabilityCase c;
    c.name = std::move(name);
    c.scene = [] { return random_cloud(200, 1234); };
    c.camera = [width, height, vertical_fov] { return axis_camera(width, height, vertical_fov); };
    return c;
  };
  cases.push_back(sized("Size_1x1", 1, 1));
  cases.push_back(sized("Size_17x9", 17, 9));
  // 4097 wide, 3 high: a 50 degree horizontal field of view (square pixels), so the three rows see a
  // thin horizontal slice of the cloud: the splats that cross y = 0.
  cases.push_back(sized("Size_4097x3", 4097, 3, 2 * std::atan(3.0 / 4097 * std::tan(25 * std::numbers::pi / 180)) *
                                                    180 / std::numbers::pi));
  {
    // The largest square image the device allows, up to 8192: a sparse scene (50 splats, 330k pairs),
    // no depth or counts (1 GiB of colour already), and only the default strategy: every other case
    // checks that the strategies agree, and each 64-megapixel frame takes seconds on lavapipe.
    StabilityCase c = sized("Size_Largest", 0, 0);
    c.scene = [] { return random_cloud(50, 8192); };
    c.camera = [] {
      const int side = int(std::min<uint32_t>(8192, testing::validated_renderer().device_info().max_image_dimension));
      return axis_camera(side, side);
    };
    c.depth_and_counts = false;
    c.default_strategy_only = true;
    c.bound = kOneCutoffFlip;
    cases.push_back(c);
  }
  // 1100000x1: 68750 tiles in a row, past the renderer's 65535 tiles per axis on any device (CPU
  // drivers allow 16384).
  for (auto [width, height] : {std::pair{0, 5}, std::pair{-1, 1}, std::pair{100000, 100000}, std::pair{1100000, 1}}) {
    StabilityCase c = sized("Size_Invalid_" + std::string(width < 0 ? "Minus" : "") + std::to_string(std::abs(width)) +
                                "x" + std::to_string(height),
                            0, 0);
    c.camera = [width, height] {
      Camera camera = axis_camera(64, 48);
      camera.width = width;
      camera.height = height;
      return camera;
    };
    c.expect = Expect::kThrow;
    c.error = "image size";
    cases.push_back(c);
  }
  return cases;
}

std::vector<StabilityCase> camera_cases() {
  std::vector<StabilityCase> cases;
  {
    // A 1e-3 degree field of view: at depth 3 the view is 5e-5 units high; the cloud is scaled to it.
    StabilityCase c;
    c.name = "Camera_Fov1em3Deg";
    c.scene = [] {
      CloudShape shape;
      shape.lo = {-3.5e-5f, -2.6e-5f, 2.9f};
      shape.hi = {3.5e-5f, 2.6e-5f, 3.1f};
      shape.log_scale_lo = -13.5f;  // 1.4e-6
      shape.log_scale_hi = -12.0f;  // 6e-6
      return random_cloud(200, 555, shape);
    };
    c.camera = [] { return axis_camera(64, 48, 1e-3); };
    cases.push_back(c);
  }
  {
    // A 179.9 degree field of view: f = 0.02 pixels; only splats at grazing angles reach the edges.
    StabilityCase c;
    c.name = "Camera_Fov179_9Deg";
    c.scene = [] {
      CloudShape shape;
      shape.lo = {-600.0f, -450.0f, 0.3f};
      shape.hi = {600.0f, 450.0f, 1.5f};
      shape.log_scale_lo = 2.0f;
      shape.log_scale_hi = 3.5f;
      return random_cloud(300, 179, shape);
    };
    c.camera = [] { return axis_camera(64, 48, 179.9); };
    cases.push_back(c);
  }
  {
    StabilityCase c;
    c.name = "Camera_PrincipalPointOffCentre";
    c.scene = [] { return random_cloud(200, 1234); };
    c.camera = [] {
      Camera camera = axis_camera(64, 48);
      camera.cx = 0.1 * camera.width;
      camera.cy = 0.9 * camera.height;
      return camera;
    };
    cases.push_back(c);
  }
  auto invalid = [](std::string name, std::function<void(Camera&)> spoil) {
    StabilityCase c;
    c.name = "Camera_Invalid_" + name;
    c.scene = [] { return base_cloud(); };
    c.camera = [spoil] {
      Camera camera = axis_camera(64, 48);
      spoil(camera);
      return camera;
    };
    c.expect = Expect::kThrow;
    c.error = "camera";
    c.reference_rejects = true;
    return c;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  cases.push_back(invalid("FxZero", [](Camera& camera) { camera.fx = 0; }));
  cases.push_back(invalid("FxNaN", [nan](Camera& camera) { camera.fx = nan; }));
  cases.push_back(invalid("FxNegative", [](Camera& camera) { camera.fx = -camera.fx; }));
  cases.push_back(invalid("RotationNaN", [nan](Camera& camera) { camera.rotation[4] = nan; }));
  cases.push_back(invalid("PositionNaN", [nan](Camera& camera) { camera.position[2] = nan; }));
  return cases;
}

std::vector<StabilityCase> all_cases() {
  std::vector<StabilityCase> all;
  // The crowds last: once a frame has had 100k splats in a tile, the shared renderer keeps compositing
  // in chunks (with a chunk state the size of the image), and the sparse 8192x8192 frame then takes
  // 14 s instead of 2.4 s on lavapipe. Each case runs alone under ctest, where the order is moot.
  for (auto group : {scale_cases, rotation_cases, opacity_colour_cases, position_cases, non_finite_cases,
                     image_size_cases, camera_cases, crowd_cases}) {
    std::vector<StabilityCase> cases = group();
    all.insert(all.end(), cases.begin(), cases.end());
  }
  return all;
}

class Hard : public ::testing::TestWithParam<StabilityCase> {};

TEST_P(Hard, Case) {
  const StabilityCase& c = GetParam();
  if (c.expect == Expect::kThrow)
    run_error_case(c);
  else
    run_render_case(c);
}

INSTANTIATE_TEST_SUITE_P(Stability, Hard, ::testing::ValuesIn(all_cases()),
                         [](const auto& param_info) { return param_info.param.name; });

// The render-or-throw crowds are compared with the reference of their first 64 splats (see
// full_screen_splats). Where the whole scene's reference is cheap, the two are the same image.
TEST(StabilitySelfCheck, FirstSplatsOfTheFullScreenCrowdDecideEveryPixel) {
  const GaussianScene scene = full_screen_splats(100'000);
  const Camera camera = axis_camera(64, 48);
  const RenderImage all = render_reference(scene, camera);
  expect_identical(render_reference(first_splats(scene, 64), camera), all, "first 64 splats vs all");
  uint32_t most = 0;
  for (uint32_t count : all.splat_count) most = std::max(most, count);
  EXPECT_EQ(most, 5u);  // five blended; T = 0.2^6 < 1e-4 stops every pixel at the 6th (see full_screen_splats)
}

}  // namespace
}  // namespace tilesplat
