// Frames that would build the same tile lists as the previous frame run only the composite
// (FrameStats::reused_sorted_lists), and upload nothing; anything that changes the lists rebuilds them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

Camera playbot_camera() {
  return resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(1).camera, 200, 120);
}

std::vector<std::string> pass_names(const FrameStats& stats) {
  std::vector<std::string> names;
  for (const PassTiming& pass : stats.passes) names.push_back(pass.name);
  return names;
}

void expect_identical(const RenderImage& a, const RenderImage& b, const std::string& what) {
  EXPECT_EQ(a.rgba, b.rgba) << what;
  EXPECT_EQ(a.depth, b.depth) << what;
  EXPECT_EQ(a.splat_count, b.splat_count) << what;
}

std::unique_ptr<Renderer> fresh_renderer() {
  RendererOptions options;
  options.validation = true;
  return Renderer::create(options);
}

TEST(FrameReuse, IdenticalFrameReusesTheListsAndIsBitIdentical) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera camera = playbot_camera();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const RenderImage first = renderer.render(camera);
  const FrameStats built = renderer.last_frame_stats();
  EXPECT_FALSE(built.reused_sorted_lists);
  EXPECT_GT(built.passes.size(), 4u);
  // The scene's upload since the previous frame: at least its attributes, 14 floats a splat.
  EXPECT_GE(built.uploaded_bytes, scene.size() * 14 * sizeof(float));

  const RenderImage second = renderer.render(camera);
  const FrameStats& reused = renderer.last_frame_stats();
  EXPECT_TRUE(reused.reused_sorted_lists);
  EXPECT_EQ(pass_names(reused), std::vector<std::string>{"composite"});
  EXPECT_EQ(reused.uploaded_bytes, 0u);
  EXPECT_EQ(reused.visible, built.visible);
  EXPECT_EQ(reused.intersections, built.intersections);
  EXPECT_EQ(reused.sort_bits, 0u);
  EXPECT_EQ(reused.retries, 0);
  EXPECT_LT(reused.gpu_ms, built.gpu_ms);
  std::printf("[ measure  ] %dx%d: full frame %.1f ms GPU, composite alone %.1f ms\n", camera.width, camera.height,
              built.gpu_ms, reused.gpu_ms);
  expect_identical(first, second, "second frame");

  // Opting out (benchmarks) builds the lists again, to the same image.
  RenderSettings rebuild;
  rebuild.reuse_lists = false;
  const RenderImage third = renderer.render(camera, rebuild);
  EXPECT_FALSE(renderer.last_frame_stats().reused_sorted_lists);
  EXPECT_EQ(pass_names(renderer.last_frame_stats()), pass_names(built));
  EXPECT_LT(renderer.last_frame_stats().uploaded_bytes, 1024u);
  expect_identical(first, third, "rebuilt frame");
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(FrameReuse, BackgroundChangeReusesAndMatchesAFreshRenderer) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera camera = playbot_camera();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  renderer.render(camera);
  RenderSettings blue;
  blue.background = {0.1f, 0.3f, 0.9f};
  const RenderImage reused = renderer.render(camera, blue);
  EXPECT_TRUE(renderer.last_frame_stats().reused_sorted_lists);

  const auto fresh = fresh_renderer();
  fresh->set_scene(scene);
  const RenderImage expected = fresh->render(camera, blue);
  EXPECT_FALSE(fresh->last_frame_stats().reused_sorted_lists);
  expect_identical(reused, expected, "background changed");
  EXPECT_EQ(fresh->validation_messages(), 0u);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(FrameReuse, TogglingOutputsReusesAndWritesThem) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera camera = playbot_camera();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const RenderImage full = renderer.render(camera);
  RenderSettings colour_only;
  colour_only.depth = false;
  colour_only.splat_count = false;
  const RenderImage colour = renderer.render(camera, colour_only);
  EXPECT_TRUE(renderer.last_frame_stats().reused_sorted_lists);
  EXPECT_EQ(colour.rgba, full.rgba);
  EXPECT_TRUE(colour.depth.empty());
  RenderSettings with_depth = colour_only;
  with_depth.depth = true;
  const RenderImage depth = renderer.render(camera, with_depth);
  EXPECT_TRUE(renderer.last_frame_stats().reused_sorted_lists);
  EXPECT_EQ(depth.depth, full.depth);
  EXPECT_TRUE(depth.splat_count.empty());
  const RenderImage again = renderer.render(camera);
  EXPECT_TRUE(renderer.last_frame_stats().reused_sorted_lists);
  expect_identical(again, full, "outputs back on");
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// Each change below alters the lists (or may): the frame rebuilds them, gives the image the same
// settings give on lists built from scratch, and the base frame after it rebuilds again.
TEST(FrameReuse, ChangesToTheListsRebuildThem) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera base_camera = playbot_camera();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const RenderImage base = renderer.render(base_camera);

  struct Change {
    std::string name;
    Camera camera;
    RenderSettings settings;
  };
  std::vector<Change> changes;
  Camera moved = base_camera;
  moved.position[0] += 1e-3;
  changes.push_back({"camera position", moved, {}});
  Camera wider = base_camera;
  wider.fx *= 0.999;
  changes.push_back({"camera focal length", wider, {}});
  changes.push_back({"image size", resize_camera(base_camera, 208, 120), {}});
  RenderSettings settings;
  settings.sort = "onesweep";
  changes.push_back({"sort strategy", base_camera, settings});
  settings = {};
  settings.accuracy.sh_degree_cap = 1;
  changes.push_back({"accuracy modes", base_camera, settings});
  settings = {};
  settings.accuracy.transmittance_cutoff = 1e-3f;
  changes.push_back({"transmittance cut-off", base_camera, settings});
  settings = {};
  settings.antialiasing = Antialiasing::kAntialiased;
  changes.push_back({"antialiasing", base_camera, settings});
  settings = {};
  settings.lighting.lights.push_back(Light{});
  settings.lighting.ambient = {0.3f, 0.3f, 0.3f};
  changes.push_back({"lighting", base_camera, settings});
  settings = {};
  settings.compositor = Compositor::kStochastic;
  settings.stochastic.frames = 2;
  changes.push_back({"compositor", base_camera, settings});

  for (const Change& change : changes) {
    const RenderImage changed = renderer.render(change.camera, change.settings);
    EXPECT_FALSE(renderer.last_frame_stats().reused_sorted_lists) << change.name;
    // The camera and light parameters (the bundled playbot has no normals to upload on its first lit frame).
    EXPECT_LT(renderer.last_frame_stats().uploaded_bytes, 1024u) << change.name;
    renderer.set_scene(scene);  // lists built from scratch
    const RenderImage expected = renderer.render(change.camera, change.settings);
    EXPECT_FALSE(renderer.last_frame_stats().reused_sorted_lists) << change.name;
    expect_identical(changed, expected, change.name);
    const RenderImage back = renderer.render(base_camera);
    EXPECT_FALSE(renderer.last_frame_stats().reused_sorted_lists) << change.name;
    expect_identical(back, base, "back from " + change.name);
  }
  // set_scene invalidates the lists even for the same scene and camera.
  renderer.set_scene(scene);
  const RenderImage after_set_scene = renderer.render(base_camera);
  EXPECT_FALSE(renderer.last_frame_stats().reused_sorted_lists);
  expect_identical(after_set_scene, base, "after set_scene");
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(FrameReuse, StochasticFramesReuseTheBinnedLists) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera camera = playbot_camera();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  RenderSettings settings;
  settings.compositor = Compositor::kStochastic;
  settings.stochastic.frames = 4;
  renderer.render(camera, settings);
  EXPECT_FALSE(renderer.last_frame_stats().reused_sorted_lists);
  settings.stochastic.frames = 6;
  settings.stochastic.seed = 9;
  settings.background = {1, 1, 1};
  const RenderImage reused = renderer.render(camera, settings);
  EXPECT_TRUE(renderer.last_frame_stats().reused_sorted_lists);
  EXPECT_EQ(pass_names(renderer.last_frame_stats()), std::vector<std::string>{"stochastic_composite"});
  renderer.set_scene(scene);
  const RenderImage expected = renderer.render(camera, settings);
  EXPECT_FALSE(renderer.last_frame_stats().reused_sorted_lists);
  expect_identical(reused, expected, "stochastic, new seed and frames");
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// A camera move re-uploads only the camera (176 bytes), whatever the scene's size; set_scene
// uploads the scene.
TEST(FrameReuse, CameraMoveUploadsOnlyTheCamera) {
  GaussianScene scene;
  scene.sh_degree = 0;
  const size_t n = 500'000;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(-1.f, 1.f);
  for (size_t i = 0; i < n; ++i) {
    scene.positions.insert(scene.positions.end(), {unit(rng), unit(rng), 3.f + unit(rng)});
    scene.log_scales.insert(scene.log_scales.end(), {-5.f, -5.f, -5.f});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(unit(rng));
    scene.sh.insert(scene.sh.end(), {unit(rng), unit(rng), unit(rng)});
  }
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 64, 64, 60);
  renderer.render(camera);
  const uint64_t scene_upload = renderer.last_frame_stats().uploaded_bytes;
  camera.position[0] += 0.01;
  renderer.render(camera);
  const FrameStats& moved = renderer.last_frame_stats();
  std::printf("[ measure  ] 500k splats: %llu bytes uploaded by set_scene and the first frame, %llu by a camera move\n",
              static_cast<unsigned long long>(scene_upload), static_cast<unsigned long long>(moved.uploaded_bytes));
  EXPECT_GE(scene_upload, n * 14 * sizeof(float));
  EXPECT_FALSE(moved.reused_sorted_lists);
  EXPECT_GT(moved.uploaded_bytes, 0u);
  EXPECT_LT(moved.uploaded_bytes, 1024u);
  renderer.render(camera);
  EXPECT_TRUE(renderer.last_frame_stats().reused_sorted_lists);
  EXPECT_EQ(renderer.last_frame_stats().uploaded_bytes, 0u);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The frame state that retries settle (grown key buffers, composite chunks) carries over: a reused
// frame after an overflowing one, or after one that needed chunks, is the same image, with no retry.
TEST(FrameReuse, ReusesListsAfterRetries) {
  // More intersections than the initial key buffers hold (as GrowsKeyBuffersWhenIntersectionsExceedCapacity).
  GaussianScene big;
  big.sh_degree = 0;
  for (int i = 0; i < 40; ++i) {
    big.positions.insert(big.positions.end(), {0.01f * float(i), 0.0f, 2.0f + 0.01f * float(i)});
    big.log_scales.insert(big.log_scales.end(), {1.0f, 1.0f, 1.0f});
    big.rotations.insert(big.rotations.end(), {1, 0, 0, 0});
    big.opacity_logits.push_back(-3.0f);
    big.sh.insert(big.sh.end(), {0.5f, 0.2f, -0.3f});
  }
  // A tile listing more splats than one composite chunk takes on CPU drivers.
  GaussianScene crowded;
  crowded.sh_degree = 0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  for (int i = 0; i < 20000; ++i) {
    const float z = 1.f + unit(rng);
    const float px = 0.5f + 15.f * unit(rng), py = 0.5f + 15.f * unit(rng);
    crowded.positions.insert(crowded.positions.end(), {(px - 8.f) * z / 16.f, (py - 8.f) * z / 16.f, z});
    const float log_scale = std::log(0.01f * z / 16.f);
    crowded.log_scales.insert(crowded.log_scales.end(), {log_scale, log_scale, log_scale});
    crowded.rotations.insert(crowded.rotations.end(), {1, 0, 0, 0});
    crowded.opacity_logits.push_back(std::log(0.02f / 0.98f));
    crowded.sh.insert(crowded.sh.end(), {unit(rng), unit(rng), unit(rng)});
  }
  Camera one_tile;
  one_tile.width = one_tile.height = 16;
  one_tile.fx = one_tile.fy = 16;
  one_tile.cx = one_tile.cy = 8;

  struct Case {
    std::string name;
    const GaussianScene& scene;
    Camera camera;
    RenderSettings settings;
  };
  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  stochastic.stochastic.frames = 3;
  const std::vector<Case> cases = {
      {"overflow", big, look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 1280, 960, 60), {}},
      {"overflow, stochastic", big, look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 1280, 960, 60), stochastic},
      {"chunks", crowded, one_tile, {}},
      {"chunks, stochastic", crowded, one_tile, stochastic},
  };
  for (const Case& c : cases) {
    const auto renderer = fresh_renderer();  // key buffers and chunk counts at their initial sizes
    renderer->set_scene(c.scene);
    const RenderImage first = renderer->render(c.camera, c.settings);
    EXPECT_GE(renderer->last_frame_stats().retries, 1) << c.name;
    const RenderImage second = renderer->render(c.camera, c.settings);
    EXPECT_TRUE(renderer->last_frame_stats().reused_sorted_lists) << c.name;
    EXPECT_EQ(renderer->last_frame_stats().retries, 0) << c.name;
    expect_identical(first, second, c.name);
    EXPECT_EQ(renderer->validation_messages(), 0u) << c.name;
  }
}

}  // namespace
}  // namespace tilesplat
