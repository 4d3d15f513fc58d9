// What the viewer shows, driven without a window or a device: the keys' cycles (modes, sorts, compositors,
// lenses, views), the toggles, and the title's words (apps/viewer/view_state.h).
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "../test_support.h"
#include "scene_loading.h"
#include "tilesplat/renderer.h"
#include "view_state.h"
#include "viewer_options.h"

namespace {

using tilesplat::viewer::ViewState;

// The viewer's own steps: its flags parsed, the scene and camera loaded, the views picked.
struct LoadedView {
  tilesplat::viewer::ViewerOptions options;
  tilesplat::cli::LoadedScene loaded;
  tilesplat::cli::SceneViews views;
};

LoadedView load(std::vector<std::string> flags) {
  LoadedView view;
  tilesplat::cli::ArgParser parser(tilesplat::viewer::kProgram, tilesplat::viewer::kUsage,
                                   tilesplat::viewer::kDescription);
  tilesplat::viewer::add_viewer_options(parser, view.options);
  flags.insert(flags.begin(), {"tilesplat-viewer", tilesplat::testing::bundled_playbot().string()});
  std::vector<const char*> argv;
  for (const std::string& flag : flags) argv.push_back(flag.c_str());
  parser.parse(int(argv.size()), argv.data());
  tilesplat::viewer::check_viewer_flags(parser, view.options);
  view.loaded = tilesplat::cli::load_scene_and_camera(view.options.common, "test",
                                                      tilesplat::cli::SceneHolding::kInstancesIfMoving);
  view.views = tilesplat::cli::camera_views(view.options.common, view.loaded);
  return view;
}

ViewState make_state(const LoadedView& view) {
  return ViewState(view.options, view.loaded, view.views);
}

// What a title shows before any frame was waited for.
std::string first_title(const ViewState& state) {
  return state.title(tilesplat::FrameStats{});
}

TEST(ViewState, ModeKeyVisitsEveryModeTheCompositorDraws) {
  const LoadedView view = load({"--width", "64", "--height", "36"});
  ViewState state = make_state(view);
  for (int compositor = 0; compositor < 3; ++compositor) {
    std::set<std::string> visited;
    for (int press = 0; press < 10; ++press) {
      const tilesplat::RenderSettings settings = state.settings();
      EXPECT_TRUE(tilesplat::compositor_draws(settings.compositor, settings.accuracy))
          << tilesplat::to_string(settings.accuracy) << " under "
          << tilesplat::to_string(settings.compositor);
      visited.insert(tilesplat::to_string(settings.accuracy));
      EXPECT_TRUE(state.press(GLFW_KEY_M));
    }
    // Every mode of the cycle the compositor draws, and no other: the reference everywhere, per-pixel
    // re-sorting with the sorted compositor alone.
    const tilesplat::Compositor shown = state.settings().compositor;
    std::set<std::string> drawn;
    for (const char* mode :
         {"reference", "depth16", "radial", "resort8", "depth16+opacity-extent+fp16-sh+fp16-cov"})
      if (tilesplat::compositor_draws(shown, tilesplat::parse_accuracy_modes(mode)))
        drawn.insert(tilesplat::to_string(tilesplat::parse_accuracy_modes(mode)));
    EXPECT_EQ(visited, drawn) << tilesplat::to_string(shown);
    EXPECT_TRUE(visited.count("reference")) << tilesplat::to_string(shown);
    EXPECT_EQ(visited.count("resort8"), shown == tilesplat::Compositor::kSorted ? 1u : 0u)
        << tilesplat::to_string(shown);
    EXPECT_TRUE(state.press(GLFW_KEY_C));
  }
  EXPECT_EQ(state.settings().compositor, tilesplat::Compositor::kSorted);  // C went round
}

TEST(ViewState, CompositorKeyCyclesSortedRasterStochasticAndTheTitleSaysWhich) {
  const LoadedView view = load({"--width", "64", "--height", "36"});
  ViewState state = make_state(view);
  EXPECT_EQ(state.settings().compositor, tilesplat::Compositor::kSorted);
  EXPECT_NE(first_title(state).find("| sorted"), std::string::npos) << first_title(state);
  state.press(GLFW_KEY_C);
  EXPECT_EQ(state.settings().compositor, tilesplat::Compositor::kRaster);
  state.press(GLFW_KEY_C);
  const tilesplat::RenderSettings stochastic = state.settings();
  EXPECT_EQ(stochastic.compositor, tilesplat::Compositor::kStochastic);
  // One frame a redraw, added to the earlier ones while nothing changes.
  EXPECT_EQ(stochastic.stochastic.frames, 1u);
  EXPECT_TRUE(stochastic.stochastic.accumulate);
  tilesplat::FrameStats last;
  last.accumulated_frames = 7;
  EXPECT_NE(state.title(last).find("stochastic (7 hash frames)"), std::string::npos) << state.title(last);
}

TEST(ViewState, SortKeyStepsFromAutoThroughEveryStrategy) {
  const LoadedView view = load({"--width", "64", "--height", "36"});
  ViewState state = make_state(view);
  EXPECT_EQ(state.settings().sort, "auto");
  tilesplat::FrameStats last;
  last.sort_strategy = "onesweep";
  EXPECT_NE(state.title(last).find("auto (onesweep)"), std::string::npos) << state.title(last);
  const std::vector<std::string> strategies = tilesplat::sort_strategies();
  for (const std::string& strategy : strategies) {
    EXPECT_TRUE(state.press(GLFW_KEY_S));
    EXPECT_EQ(state.settings().sort, strategy);
  }
  state.press(GLFW_KEY_S);
  EXPECT_EQ(state.settings().sort, "auto");
}

TEST(ViewState, ViewKeysStepThroughTheCamerasAndWrapAround) {
  const LoadedView view = load({"--width", "64", "--height", "36", "--cameras",
                                tilesplat::testing::bundled_playbot_cameras().string()});
  ASSERT_GE(view.views.views.size(), 2u);
  const int count = int(view.views.views.size());
  ViewState state = make_state(view);
  EXPECT_NE(first_title(state).find("view 0"), std::string::npos) << first_title(state);
  EXPECT_TRUE(state.press(GLFW_KEY_N));
  EXPECT_NE(first_title(state).find("view 1"), std::string::npos) << first_title(state);
  EXPECT_EQ(state.pinhole_camera().position, view.views.views[1].camera.position);
  EXPECT_TRUE(state.press(GLFW_KEY_LEFT));
  EXPECT_TRUE(state.press(GLFW_KEY_P));  // from the first view to the last
  EXPECT_NE(first_title(state).find("view " + std::to_string(count - 1)), std::string::npos)
      << first_title(state);
  EXPECT_EQ(state.pinhole_camera().position, view.views.views[size_t(count - 1)].camera.position);
}

TEST(ViewState, KeysThatChangeNothingAskForNoFrame) {
  const LoadedView view = load({"--width", "64", "--height", "36"});  // the mesh is drawn, no views
  ViewState state = make_state(view);
  EXPECT_FALSE(state.press(GLFW_KEY_N));  // no views to step through
  EXPECT_FALSE(state.press(GLFW_KEY_P));
  EXPECT_FALSE(state.press(GLFW_KEY_F));  // depth of field and motion blur are not drawn with the mesh
  EXPECT_FALSE(state.press(GLFW_KEY_B));
  EXPECT_FALSE(state.press(GLFW_KEY_X));  // no key of the viewer's
  EXPECT_TRUE(state.depth_out());
  EXPECT_TRUE(state.press(GLFW_KEY_D));
  EXPECT_FALSE(state.depth_out());
}

TEST(ViewState, LensKeyStepsThroughPinholeFisheyeAndPanoramaWithoutTheMesh) {
  const LoadedView view = load({"--width", "64", "--height", "32", "--no-mesh"});
  ViewState state = make_state(view);
  EXPECT_NE(first_title(state).find("pinhole"), std::string::npos) << first_title(state);
  state.press(GLFW_KEY_L);
  EXPECT_NE(first_title(state).find("fisheye 180 deg"), std::string::npos) << first_title(state);
  EXPECT_NE(state.camera().model, state.pinhole_camera().model);
  state.press(GLFW_KEY_L);
  EXPECT_NE(first_title(state).find("panorama"), std::string::npos) << first_title(state);
  state.press(GLFW_KEY_L);
  EXPECT_EQ(state.camera().model, state.pinhole_camera().model);
}

}  // namespace
