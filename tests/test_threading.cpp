// What docs/embedding.md promises about threads: several renderers render at once on several
// threads, and the free functions (readers, writers, the reference) run concurrently on their own
// data, each giving what one thread alone gives.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace {

namespace fs = std::filesystem;
using tilesplat::Camera;
using tilesplat::GaussianScene;
using tilesplat::RenderImage;

void expect_same_image(const RenderImage& a, const RenderImage& b, const std::string& what) {
  EXPECT_EQ(a.width, b.width) << what;
  EXPECT_EQ(a.rgba, b.rgba) << what;
  EXPECT_EQ(a.depth, b.depth) << what;
  EXPECT_EQ(a.splat_count, b.splat_count) << what;
}

TEST(Threading, TwoRenderersOnTwoThreadsRenderWhatOneThreadRenders) {
  const GaussianScene scene = tilesplat::load_scene(tilesplat::testing::bundled_playbot());
  const std::vector<Camera> cameras = {tilesplat::orbit_camera(scene, 160, 90, {.azimuth_deg = 0}),
                                       tilesplat::orbit_camera(scene, 160, 90, {.azimuth_deg = 120})};
  const std::vector<std::string> sorts = {"radix", "onesweep"};

  // One thread, one renderer: the expected images.
  std::vector<RenderImage> expected;
  {
    const auto renderer = tilesplat::Renderer::create();
    renderer->set_scene(scene);
    for (size_t t = 0; t < cameras.size(); ++t) {
      tilesplat::RenderSettings settings;
      settings.sort = sorts[t];
      expected.push_back(renderer->render(cameras[t], settings));
    }
  }

  // Two threads, each with its own renderer, rendering at the same time, several frames each.
  constexpr int kFrames = 4;
  std::vector<std::vector<RenderImage>> images(cameras.size());
  std::vector<uint64_t> messages(cameras.size(), 0);
  std::vector<std::string> errors(cameras.size());
  std::vector<std::thread> threads;
  for (size_t t = 0; t < cameras.size(); ++t) {
    threads.emplace_back([&, t] {
      try {
        const auto renderer = tilesplat::Renderer::create();
        renderer->set_scene(scene);
        tilesplat::RenderSettings settings;
        settings.sort = sorts[t];
        settings.reuse_lists = false;  // every frame a whole frame
        for (int frame = 0; frame < kFrames; ++frame)
          images[t].push_back(renderer->render(cameras[t], settings));
        messages[t] = renderer->validation_messages();
      } catch (const std::exception& error) {
        errors[t] = error.what();
      }
    });
  }
  for (auto& thread : threads) thread.join();
  for (size_t t = 0; t < cameras.size(); ++t) {
    EXPECT_EQ(errors[t], "") << "thread " << t;
    EXPECT_EQ(messages[t], 0u) << "thread " << t;
    ASSERT_EQ(images[t].size(), size_t(kFrames)) << "thread " << t;
    for (int frame = 0; frame < kFrames; ++frame)
      expect_same_image(images[t][frame], expected[t],
                        "thread " + std::to_string(t) + " frame " + std::to_string(frame));
  }
}

TEST(Threading, ReadersWritersAndTheReferenceRunConcurrently) {
  const fs::path playbot = tilesplat::testing::bundled_playbot();
  const fs::path sh3 = tilesplat::testing::bundled_sh3();
  const fs::path out = tilesplat::testing::fresh_output_dir();

  // Alone first.
  const GaussianScene playbot_scene = tilesplat::load_scene(playbot);
  const GaussianScene sh3_scene = tilesplat::load_scene(sh3);
  const Camera camera = tilesplat::orbit_camera(sh3_scene, 48, 27);
  const RenderImage reference = tilesplat::render_reference(sh3_scene, camera);

  constexpr int kThreads = 4;
  std::vector<std::string> errors(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      try {
        for (int round = 0; round < 3; ++round) {
          const GaussianScene a = tilesplat::load_scene(t % 2 ? playbot : sh3);
          const GaussianScene& expected = t % 2 ? playbot_scene : sh3_scene;
          if (a.positions != expected.positions || a.sh != expected.sh || a.rotations != expected.rotations)
            throw std::runtime_error("a concurrent load read a different scene");
          const RenderImage image = tilesplat::render_reference(sh3_scene, camera);
          if (image.rgba != reference.rgba) throw std::runtime_error("a concurrent reference render differs");
          const fs::path file = out / ("thread" + std::to_string(t) + ".exr");
          // The display encoding stores the values as they are, so that the read back is bit-exact.
          tilesplat::write_exr(file, image, {.colour = tilesplat::ColourEncoding::kSrgbDisplay});
          if (tilesplat::read_exr(file).rgba != image.rgba)
            throw std::runtime_error("an EXR read back differs");
        }
      } catch (const std::exception& error) {
        errors[t] = error.what();
      }
    });
  }
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(errors[t], "") << "thread " << t;
  EXPECT_EQ(tilesplat::testing::entries(out).size(), size_t(kThreads));  // no temporary left behind
}

}  // namespace
