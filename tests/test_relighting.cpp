// Relighting (tilesplat::Lighting, issue 6): the float64 reference against the model's formula on
// single splats, the GPU against the reference on synthetic and real scenes, lighting off leaving the
// frame untouched, and invalid lights refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "cli.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {
namespace {

constexpr double kShC0 = 0.28209479177387814;

using tilesplat::testing::axis_camera;

// One splat at (0, 0, 2): flat along its local z (log scale -9), rotation w x y z, colour from its DC
// term, which the unlit colour max(C0 dc + 0.5, 0) reproduces.
GaussianScene flat_splat(const std::array<float, 4>& rotation = {1, 0, 0, 0}) {
  GaussianScene scene;
  scene.positions = {0, 0, 2};
  scene.log_scales = {std::log(0.05f), std::log(0.05f), -9.0f};
  scene.rotations = {rotation[0], rotation[1], rotation[2], rotation[3]};
  scene.opacity_logits = {2};
  scene.sh = {0.4f, 0.1f, -0.3f};
  return scene;
}

Light directional(std::array<float, 3> direction, float intensity = 1, std::array<float, 3> color = {1, 1, 1}) {
  Light light;
  light.direction = direction;
  light.intensity = intensity;
  light.color = color;
  return light;
}

Light point(std::array<float, 3> position, float intensity = 1, std::array<float, 3> color = {1, 1, 1}) {
  Light light;
  light.type = Light::Type::kPoint;
  light.position = position;
  light.intensity = intensity;
  light.color = color;
  return light;
}

std::array<double, 3> unlit_colour(const GaussianScene& scene, const Camera& camera) {
  const ProjectedGaussian g = project_gaussian(scene, 0, camera);
  EXPECT_TRUE(g.visible);
  return {g.color[0], g.color[1], g.color[2]};
}

void expect_colour(const ProjectedGaussian& g, const std::array<double, 3>& expected, const char* what) {
  ASSERT_TRUE(g.visible) << what;
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(g.color[c], expected[c], 1e-12) << what << " channel " << c;
}

std::array<double, 3> times(const std::array<double, 3>& colour, double factor) {
  return {colour[0] * factor, colour[1] * factor, colour[2] * factor};
}

// ---------------------------------------------------------------------------------------------
// The reference against the model's formula

TEST(ReferenceRelighting, FlatSplatFollowsLambert) {
  const Camera camera = axis_camera(64, 64, 100);
  const GaussianScene scene = flat_splat();  // shortest axis z; turned toward the camera: -z
  const std::array<double, 3> colour = unlit_colour(scene, camera);
  EXPECT_NEAR(colour[0], kShC0 * double(0.4f) + 0.5, 1e-12);

  Lighting lighting;
  lighting.lights = {directional({0, 0, 1}, 2)};  // travels +z: head-on onto the -z normal
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting), times(colour, 2), "head-on");

  // 60 degrees between the normal and the light: cos = 1/2.
  const float s60 = float(std::sin(std::numbers::pi / 3)), c60 = float(std::cos(std::numbers::pi / 3));
  lighting.lights = {directional({s60, 0, c60}, 2)};
  const double cosine = double(c60) / std::hypot(double(s60), double(c60));  // the float direction's own
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting), times(colour, 2 * cosine),
                "60 degrees");
  EXPECT_NEAR(cosine, 0.5, 1e-7);

  // From behind the splat (travelling toward the camera): the camera-side face is dark, and only
  // the ambient remains.
  lighting.lights = {directional({0, 0, -1}, 2)};
  lighting.ambient = {0.25f, 0.5f, 0.125f};
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting),
                {colour[0] * 0.25, colour[1] * 0.5, colour[2] * 0.125}, "from behind, ambient only");

  // Ambient adds to the lights, per channel, and light colours multiply.
  lighting.lights = {directional({0, 0, 1}, 2, {1, 0.5f, 0})};
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting),
                {colour[0] * 2.25, colour[1] * 1.5, colour[2] * 0.125}, "coloured light and ambient");
}

TEST(ReferenceRelighting, NormalsComeFromTheFileOrTheShortestAxisFacingTheCamera) {
  const Camera camera = axis_camera(64, 64, 100);
  Lighting lighting;
  lighting.lights = {directional({0, 0, 1})};  // lights a normal of -z fully, +-x and +-y not at all

  // The splat's shortest axis turned by 90 degrees about y: local z becomes world x, lit edge-on.
  const float h = float(std::sqrt(0.5));
  GaussianScene turned = flat_splat({h, 0, h, 0});
  const std::array<double, 3> colour = unlit_colour(turned, camera);
  const ProjectedGaussian edge_on = project_gaussian(turned, 0, camera, Antialiasing::kClassic, lighting);
  ASSERT_TRUE(edge_on.visible);
  EXPECT_LE(edge_on.color[0], 1e-7 * colour[0]);

  // A file normal overrides the axis. Pointing away from the camera (+z), it is turned around: lit.
  turned.normals = {0, 0, 1};
  expect_colour(project_gaussian(turned, 0, camera, Antialiasing::kClassic, lighting), colour, "file normal, flipped");
  // Not unit length: normalised.
  turned.normals = {0, 0, -5};
  expect_colour(project_gaussian(turned, 0, camera, Antialiasing::kClassic, lighting), colour, "file normal, length 5");
  // 60 degrees off the light: half.
  turned.normals = {float(std::sqrt(3.0)), 0, -1};
  const double half = double(-turned.normals[2]) / std::hypot(double(turned.normals[0]), double(turned.normals[2]));
  expect_colour(project_gaussian(turned, 0, camera, Antialiasing::kClassic, lighting), times(colour, half),
                "file normal at 60 degrees");
  // Zero (the original trainer's), non-finite and denormal normals fall back to the shortest axis.
  for (const std::array<float, 3> unusable :
       {std::array<float, 3>{0, 0, 0}, {std::numeric_limits<float>::quiet_NaN(), 0, 1},
        {std::numeric_limits<float>::infinity(), 0, 0}, {1e-40f, 0, 0}}) {
    turned.normals = {unusable[0], unusable[1], unusable[2]};
    const ProjectedGaussian g = project_gaussian(turned, 0, camera, Antialiasing::kClassic, lighting);
    ASSERT_TRUE(g.visible);
    EXPECT_EQ(g.color[0], edge_on.color[0]) << unusable[0] << " " << unusable[1] << " " << unusable[2];
  }

  // The shortest axis is the smallest scale's, whichever index it has.
  GaussianScene x_thin = flat_splat();
  x_thin.log_scales = {-9.0f, std::log(0.05f), std::log(0.05f)};  // thin along x: edge-on
  EXPECT_LE(project_gaussian(x_thin, 0, camera, Antialiasing::kClassic, lighting).color[0], 1e-7);
}

TEST(ReferenceRelighting, PointLightFallsOffWithTheSquaredDistance) {
  const Camera camera = axis_camera(64, 64, 100);
  const GaussianScene scene = flat_splat();
  const std::array<double, 3> colour = unlit_colour(scene, camera);
  Lighting lighting;
  lighting.lights = {point({0, 0, 0}, 3)};  // at the camera, distance 2, straight onto the normal
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting), times(colour, 3.0 / 4.0),
                "distance 2");
  lighting.lights = {point({0, 0, 1.5f}, 3)};  // distance 0.5
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting), times(colour, 12.0),
                "distance 0.5");
  // Exactly at the splat: no direction, no light (and no NaN); the ambient still applies.
  lighting.lights = {point({0, 0, 2}, 3)};
  lighting.ambient = {0.5f, 0.5f, 0.5f};
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting), times(colour, 0.5),
                "at the light");
  // Behind the splat: dark.
  lighting.lights = {point({0, 0, 4}, 3)};
  lighting.ambient = {};
  expect_colour(project_gaussian(scene, 0, camera, Antialiasing::kClassic, lighting), {0, 0, 0}, "behind");
}

// ---------------------------------------------------------------------------------------------
// The GPU against the reference

// Splats in front of an axis camera: random positions, rotations and anisotropic scales (some
// flat), SH degree 1, and normals when asked. The normals have their own random stream, so that
// every kind of normals comes with the same splats.
enum class Normals { kNone, kRandom, kZero, kMixed };
GaussianScene synthetic_scene(int count, Normals normals, uint32_t seed) {
  std::mt19937 rng(seed), normal_rng(seed + 1);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  std::normal_distribution<float> gauss(0.f, 1.f);
  auto random_normal = [&] {
    return std::array<float, 3>{gauss(normal_rng), gauss(normal_rng), gauss(normal_rng)};
  };
  GaussianScene scene;
  scene.sh_degree = 1;
  for (int i = 0; i < count; ++i) {
    const float z = 1.5f + 3.f * unit(rng);
    scene.positions.insert(scene.positions.end(), {(unit(rng) - 0.5f) * z, (unit(rng) - 0.5f) * 0.75f * z, z});
    const float thin = unit(rng) < 0.5f ? -7.f : std::log(0.02f);
    scene.log_scales.insert(scene.log_scales.end(),
                            {std::log(0.03f + 0.05f * unit(rng)), std::log(0.03f + 0.05f * unit(rng)), thin});
    scene.rotations.insert(scene.rotations.end(), {gauss(rng), gauss(rng), gauss(rng), gauss(rng)});
    scene.opacity_logits.push_back(2.f * gauss(rng));
    for (int k = 0; k < 4 * 3; ++k) scene.sh.push_back(k < 3 ? gauss(rng) : 0.3f * gauss(rng));
    switch (normals) {
      case Normals::kNone: break;
      case Normals::kRandom: {
        const auto n = random_normal();
        scene.normals.insert(scene.normals.end(), n.begin(), n.end());
        break;
      }
      case Normals::kZero: scene.normals.insert(scene.normals.end(), {0, 0, 0}); break;
      case Normals::kMixed: {  // usable, zero, NaN, infinite and denormal normals side by side
        const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
        const std::array<std::array<float, 3>, 5> kinds = {
            {random_normal(), {0, 0, 0}, {nan, 1, 0}, {0, inf, 0}, {1e-40f, 0, -1e-41f}}};
        const auto& n = kinds[size_t(i) % kinds.size()];
        scene.normals.insert(scene.normals.end(), n.begin(), n.end());
        break;
      }
    }
  }
  return scene;
}

Lighting test_lighting(bool directional_light, bool point_light, bool ambient) {
  Lighting lighting;
  if (directional_light) lighting.lights.push_back(directional({0.3f, 0.8f, 0.6f}, 0.9f, {1, 0.9f, 0.7f}));
  if (point_light) lighting.lights.push_back(point({-0.5f, -1.0f, 1.5f}, 1.5f, {0.8f, 0.9f, 1}));
  if (ambient) lighting.ambient = {0.15f, 0.15f, 0.2f};
  return lighting;
}

struct Tolerance {
  double min_psnr_db = 60;
  double max_abs = 2e-3;  // as AntialiasingVsReference: the unlit GPU's own error on real scenes
};

ImageDifference expect_matches_reference(const std::string& name, const GaussianScene& scene, const Camera& camera,
                                         const RenderSettings& settings, Tolerance bounds = {}) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const RenderImage gpu = renderer.render(camera, settings);
  const RenderImage ref = render_reference(scene, camera, settings);
  size_t non_finite = 0;
  for (float v : gpu.rgba) non_finite += !std::isfinite(v);
  EXPECT_EQ(non_finite, 0u) << name;
  const ImageDifference d = compare_images(gpu, ref);
  double peak = 0;
  for (size_t i = 0; i < ref.pixels(); ++i)
    for (size_t c = 0; c < 3; ++c) peak = std::max(peak, double(ref.rgba[4 * i + c]));
  std::printf("[ measure  ] relighting %s: GPU vs float64 reference PSNR %.2f dB, max abs %.2e (brightest %.2f)\n",
              name.c_str(), d.psnr_db, d.max_abs, peak);
  EXPECT_GE(d.psnr_db, bounds.min_psnr_db) << name;
  EXPECT_LE(d.max_abs, bounds.max_abs) << name;
  EXPECT_EQ(renderer.validation_messages(), 0u) << name;
  return d;
}

struct SyntheticCase {
  std::string name;
  Normals normals;
  bool directional_light, point_light, ambient;
};

class RelightingVsReference : public ::testing::TestWithParam<SyntheticCase> {};

TEST_P(RelightingVsReference, SyntheticSceneMatchesFloat64Reference) {
  const SyntheticCase& c = GetParam();
  const GaussianScene scene = synthetic_scene(3000, c.normals, 11);
  const Camera camera = axis_camera(160, 120, 120);
  RenderSettings settings;
  settings.lighting = test_lighting(c.directional_light, c.point_light, c.ambient);
  const ImageDifference lit = expect_matches_reference(c.name, scene, camera, settings);
  // The lights must matter: lit and unlit differ by far more than the GPU's error.
  const ImageDifference vs_unlit = compare_images(render_reference(scene, camera, settings),
                                                  render_reference(scene, camera, RenderSettings{}));
  EXPECT_GT(vs_unlit.max_abs, 100 * lit.max_abs) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RelightingVsReference,
    ::testing::Values(SyntheticCase{"directional_axis", Normals::kNone, true, false, false},
                      SyntheticCase{"point_axis", Normals::kNone, false, true, false},
                      SyntheticCase{"both_ambient_axis", Normals::kNone, true, true, true},
                      SyntheticCase{"both_ambient_file_normals", Normals::kRandom, true, true, true},
                      SyntheticCase{"both_ambient_zero_normals", Normals::kZero, true, true, true},
                      SyntheticCase{"both_ambient_mixed_normals", Normals::kMixed, true, true, true}),
    [](const auto& param_info) { return param_info.param.name; });

TEST(Relighting, ZeroFileNormalsRenderAsNoNormals) {
  // The original trainer's files: every normal zero. The shortest axes, bit for bit.
  const Camera camera = axis_camera(96, 72, 80);
  RenderSettings settings;
  settings.lighting = test_lighting(true, true, true);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(synthetic_scene(1000, Normals::kNone, 5));
  const RenderImage without = renderer.render(camera, settings);
  renderer.set_scene(synthetic_scene(1000, Normals::kZero, 5));
  const RenderImage zeros = renderer.render(camera, settings);
  EXPECT_EQ(without.rgba, zeros.rgba);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(Relighting, SplatAtAPointLightGetsNoLightFromIt) {
  GaussianScene scene = synthetic_scene(200, Normals::kRandom, 3);
  const Camera camera = axis_camera(64, 48, 60);
  // Splat 0 sits exactly on the light: d = 0, no direction, no light from it; the ambient remains.
  scene.positions[0] = 0.25f;
  scene.positions[1] = -0.125f;
  scene.positions[2] = 2.0f;
  scene.opacity_logits[0] = 5;
  RenderSettings settings;
  settings.lighting.lights = {point({0.25f, -0.125f, 2.0f}, 2)};
  settings.lighting.ambient = {0.5f, 0.5f, 0.5f};
  const ProjectedGaussian lit = project_gaussian(scene, 0, camera, Antialiasing::kClassic, settings.lighting);
  const ProjectedGaussian unlit = project_gaussian(scene, 0, camera);
  ASSERT_TRUE(lit.visible);
  for (size_t c = 0; c < 3; ++c) EXPECT_EQ(lit.color[c], unlit.color[c] * 0.5);
  expect_matches_reference("splat_at_point_light", scene, camera, settings);
}

// The bundled real scene (its file normals are all zero: the shortest axes), and the same scene with
// made-up file normals; 160x90 like AntialiasingVsReference, the two views it uses.
TEST(Relighting, RealSceneMatchesFloat64Reference) {
  GaussianScene scene = load_scene(testing::bundled_playbot());
  const auto views = load_cameras_json(testing::bundled_playbot_cameras());
  RenderSettings settings;
  // Lights placed around the scene's centre, in its units.
  const Bounds b = compute_bounds(scene);
  settings.lighting.lights = {directional({0.2f, 1.0f, 0.4f}, 1.2f, {1, 0.95f, 0.85f}),
                              point({float(b.center[0] + b.radius), float(b.center[1] - b.radius),
                                     float(b.center[2] - b.radius)},
                                    float(2 * b.radius * b.radius), {0.8f, 0.85f, 1})};
  settings.lighting.ambient = {0.2f, 0.2f, 0.25f};
  for (int view : {0, 3}) {
    const Camera camera = resize_camera(views.at(size_t(view)).camera, 160, 90);
    expect_matches_reference("playbot view " + std::to_string(view) + " (shortest axes)", scene, camera, settings);
  }
  // Made-up file normals: each splat's position from the centre (a sphere's normals).
  scene.normals.resize(scene.positions.size());
  for (size_t i = 0; i < scene.positions.size(); ++i) scene.normals[i] = float(scene.positions[i] - b.center[i % 3]);
  for (int view : {0, 3}) {
    const Camera camera = resize_camera(views.at(size_t(view)).camera, 160, 90);
    expect_matches_reference("playbot view " + std::to_string(view) + " (file normals)", scene, camera, settings);
  }
}

// The bundled scene file with lights (scenes/playbot_relit.json), through the apps' mapping of its
// effects: it renders lit, as the reference does, with no validation message.
TEST(Relighting, BundledRelitSceneFileMatchesFloat64Reference) {
  const SceneDescription description = load_scene_description(testing::bundled_scene_dir() / "playbot_relit.json");
  ASSERT_EQ(description.effects.lights.size(), 2u);
  const GaussianScene scene = load_described_scene(description);
  RenderSettings settings;
  cli::LoadedScene loaded;
  loaded.description = description;
  cli::apply_scene_settings(loaded, settings);
  ASSERT_TRUE(settings.lighting.enabled());
  EXPECT_EQ(settings.lighting.ambient, (std::array<float, 3>{0.12f, 0.12f, 0.15f}));
  for (const CameraView& view : description.cameras) {
    const Camera camera = resize_camera(view.camera, 160, 90);
    expect_matches_reference("playbot_relit.json " + view.name, scene, camera, settings);
    // The same frame unlit, for scale: the GPU's own error at the reference's discontinuities.
    RenderSettings unlit = settings;
    unlit.lighting = {};
    expect_matches_reference("playbot_relit.json " + view.name + " unlit", scene, camera, unlit);
  }
}

// ---------------------------------------------------------------------------------------------
// Lighting off, and invalid lights

TEST(Relighting, OffLeavesTheFrameAndMemoryUntouched) {
  const Camera camera = axis_camera(96, 72, 80);
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene with_normals = synthetic_scene(1000, Normals::kRandom, 9);
  GaussianScene without_normals = with_normals;
  without_normals.normals.clear();

  renderer.set_scene(without_normals);
  const RenderImage plain = renderer.render(camera);
  const uint64_t bytes_without = renderer.last_frame_stats().device_bytes;
  renderer.set_scene(with_normals);
  RenderSettings ambient_only;  // an ambient without lights is no lighting
  ambient_only.lighting.ambient = {0.5f, 0.5f, 0.5f};
  const RenderImage unlit = renderer.render(camera, ambient_only);
  EXPECT_EQ(plain.rgba, unlit.rgba);  // bit-identical
  EXPECT_EQ(plain.depth, unlit.depth);
  // The normals are not on the device until a frame is lit...
  EXPECT_EQ(renderer.last_frame_stats().device_bytes, bytes_without);
  // ...and then they are, once.
  RenderSettings lit;
  lit.lighting = test_lighting(true, false, false);
  const RenderImage lit_image = renderer.render(camera, lit);
  const uint64_t normal_bytes = 3 * sizeof(float) * with_normals.size();
  EXPECT_EQ(renderer.last_frame_stats().device_bytes, bytes_without + normal_bytes);
  EXPECT_NE(lit_image.rgba, plain.rgba);
  EXPECT_EQ(renderer.render(camera).rgba, plain.rgba);  // off again: the same frame as before
  EXPECT_EQ(renderer.last_frame_stats().device_bytes, bytes_without + normal_bytes);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(Relighting, InvalidLightsAreRefusedByName) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    Lighting lighting;
    std::string message;
  };
  Lighting base;
  base.lights = {directional({0, 1, 0}), point({0, 0, 0})};
  std::vector<Case> cases;
  auto add = [&](auto change, const std::string& message) {
    Lighting l = base;
    change(l);
    cases.push_back({l, message});
  };
  add([&](Lighting& l) { l.lights[0].direction = {nan, 0, 1}; }, "lighting.lights[0].direction: must be finite");
  add([](Lighting& l) { l.lights[0].direction = {0, 0, 0}; }, "lighting.lights[0].direction: must not be zero");
  add([](Lighting& l) { l.lights[1].intensity = -1; }, "lighting.lights[1].intensity: must be finite and non-negative");
  add([&](Lighting& l) { l.lights[1].position = {0, nan, 0}; }, "lighting.lights[1].position: must be finite");
  add([](Lighting& l) { l.lights[1].color = {1, -0.5f, 1}; }, "lighting.lights[1].color: must be finite and non-negative");
  add([](Lighting& l) { l.ambient = {0, 0, -1}; }, "lighting.ambient: must be finite and non-negative");

  const GaussianScene scene = flat_splat();
  const Camera camera = axis_camera(32, 32, 50);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  for (const Case& c : cases) {
    RenderSettings settings;
    settings.lighting = c.lighting;
    auto expect_refused = [&](const auto& call, const char* who) {
      try {
        call();
        ADD_FAILURE() << who << " accepted lights that should fail with: " << c.message;
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << who << ": " << e.what();
      }
    };
    expect_refused([&] { validate(c.lighting); }, "validate");
    expect_refused([&] { renderer.render(camera, settings); }, "Renderer::render");
    expect_refused([&] { render_reference(scene, camera, settings); }, "render_reference");
    expect_refused([&] { project_gaussian(scene, 0, camera, Antialiasing::kClassic, c.lighting); }, "project_gaussian");
  }
  // The renderer is still usable after a refused frame.
  RenderSettings fine;
  fine.lighting = base;
  EXPECT_NO_THROW(renderer.render(camera, fine));
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

}  // namespace
}  // namespace tilesplat
