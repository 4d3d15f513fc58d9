// Level-of-detail sets (tilesplat/lod_set.h) on tests/data/playbot_lod_set, a set splat-transform 3.7.0
// made of the bundled playbot (3 levels, 42 chunks, 17 chunk files): the index, the levels' slices,
// the choice of levels under a splat budget, the index's errors, and tilesplat-render and
// tilesplat-info on it.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <latch>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace {

namespace fs = std::filesystem;
using tilesplat::LodSelection;
using tilesplat::LodSet;
using tilesplat::SceneError;
using tilesplat::testing::fresh_output_dir;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

tilesplat::testing::ProcessResult run_process(const char* exe, const std::vector<std::string>& args) {
  return tilesplat::testing::run_process("", exe, args);
}

fs::path lod_set_dir() {
  return fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "playbot_lod_set";
}
fs::path lod_index() {
  return lod_set_dir() / "lod-meta.json";
}

std::string index_text() {
  std::ifstream in(lod_index(), std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The error LodSet::parse gives for the test set's index edited by `edit`.
std::string parse_error(const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json index = nlohmann::json::parse(index_text());
  edit(index);
  try {
    LodSet::parse(index.dump(), lod_index());
  } catch (const SceneError& error) {
    return error.what();
  }
  return "no error";
}

// The index's first leaf, five levels down its tree.
nlohmann::json& first_leaf(nlohmann::json& index) {
  nlohmann::json* node = &index["tree"];
  for (int depth = 0; depth < 5; ++depth) node = &(*node)["children"][0];
  return *node;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

bool same_scene(const tilesplat::GaussianScene& a, const tilesplat::GaussianScene& b) {
  return a.sh_degree == b.sh_degree && same_bits(a.positions, b.positions) &&
         same_bits(a.log_scales, b.log_scales) && same_bits(a.rotations, b.rotations) &&
         same_bits(a.opacity_logits, b.opacity_logits) && same_bits(a.sh, b.sh) &&
         same_bits(a.normals, b.normals);
}

// The bundled playbot's first view at 160x90: it sees the whole capture.
tilesplat::Camera whole_view() {
  tilesplat::Camera camera =
      tilesplat::load_cameras_json(tilesplat::testing::bundled_playbot_cameras()).at(0).camera;
  const double scale = 160.0 / camera.width;
  camera.fx *= scale;
  camera.fy *= scale;
  camera.cx *= scale;
  camera.cy *= scale;
  camera.width = 160;
  camera.height = 90;
  return camera;
}

TEST(LodSet, ReadsTheIndexOfSplatTransformsSet) {
  const LodSet set = LodSet::open(lod_index());
  EXPECT_EQ(set.levels(), 3);
  EXPECT_EQ(set.level_size(0), 31000u);
  EXPECT_EQ(set.level_size(1), 7750u);
  EXPECT_EQ(set.level_size(2), 1550u);
  EXPECT_EQ(set.chunks().size(), 42u);
  EXPECT_EQ(set.files().size(), 17u);
  EXPECT_FALSE(set.environment().has_value());
  EXPECT_EQ(set.environment_size(), 0u);
  EXPECT_EQ(set.generator(), "splat-transform v3.7.0");
  EXPECT_TRUE(tilesplat::is_lod_set(lod_index()));
  EXPECT_FALSE(tilesplat::is_lod_set(lod_set_dir() / "0_0" / "meta.json"));
  EXPECT_FALSE(tilesplat::is_lod_set(tilesplat::testing::bundled_playbot()));
  EXPECT_THROW(set.level_size(3), SceneError);
}

// Every level's Gaussians, chunk by chunk, lie in their chunk's box: the slices are read at the right
// offsets of the right files. The finest level is the whole capture: as many Gaussians as the PLY it
// was made from, and what load_scene reads for the index.
TEST(LodSet, EachLevelsChunksHoldTheirOwnGaussians) {
  const LodSet set = LodSet::open(lod_index());
  for (int level = 0; level < set.levels(); ++level) {
    const tilesplat::GaussianScene scene = set.load_level(level);
    ASSERT_EQ(scene.size(), set.level_size(level));
    EXPECT_EQ(scene.sh_degree, 2);
    size_t next = 0;
    for (size_t c = 0; c < set.chunks().size(); ++c) {
      const tilesplat::LodChunk& chunk = set.chunks()[c];
      for (uint64_t i = 0; i < chunk.levels[size_t(level)].count; ++i, ++next)
        for (size_t a = 0; a < 3; ++a) {
          const double p = scene.positions[3 * next + a];
          // The box is the chunk's Gaussians' one-sigma boxes, computed in float: allow its rounding.
          ASSERT_GE(p, chunk.min[a] - 1e-6) << "level " << level << " chunk " << c << " Gaussian " << i;
          ASSERT_LE(p, chunk.max[a] + 1e-6) << "level " << level << " chunk " << c << " Gaussian " << i;
        }
    }
    EXPECT_EQ(next, scene.size());
  }
  tilesplat::LoadReport report;
  const tilesplat::GaussianScene through_load_scene = tilesplat::load_scene(lod_index(), {}, &report);
  EXPECT_TRUE(same_scene(through_load_scene, set.load_level(0)));
  EXPECT_EQ(report.format, "lod set (level 0 of 3)");
  EXPECT_EQ(through_load_scene.size(), tilesplat::load_ply(tilesplat::testing::bundled_playbot()).size());
}

TEST(LodSet, ASplatBudgetRefinesTheChunksThatCoverMostPixelsFirst) {
  const LodSet set = LodSet::open(lod_index());
  const tilesplat::Camera camera = whole_view();

  const LodSelection everything = tilesplat::select_lod_levels(set, camera, 1000000);
  EXPECT_EQ(everything.splats, 31000u);
  EXPECT_FALSE(everything.over_budget);
  EXPECT_TRUE(std::all_of(everything.chunk_levels.begin(), everything.chunk_levels.end(),
                          [](int level) { return level == 0; }));
  EXPECT_TRUE(same_scene(set.load_selection(everything), set.load_level(0)));

  const LodSelection tiny = tilesplat::select_lod_levels(set, camera, 100);
  EXPECT_TRUE(tiny.over_budget);
  EXPECT_EQ(tiny.splats, 1550u);
  EXPECT_EQ(tiny.coarsest_splats, 1550u);
  EXPECT_TRUE(same_scene(set.load_selection(tiny), set.load_level(2)));

  // Between the two: within the budget, more with more budget, and never a level that is not needed.
  uint64_t previous = 0;
  for (const uint64_t budget : {2000u, 5000u, 10000u, 20000u, 30000u}) {
    const LodSelection selection = tilesplat::select_lod_levels(set, camera, budget);
    EXPECT_FALSE(selection.over_budget);
    EXPECT_LE(selection.splats, budget);
    EXPECT_GE(selection.splats, previous);
    uint64_t drawn = 0;
    for (size_t c = 0; c < set.chunks().size(); ++c) {
      ASSERT_GE(selection.chunk_levels[c], 0);
      drawn += set.chunks()[c].levels[size_t(selection.chunk_levels[c])].count;
    }
    EXPECT_EQ(drawn, selection.splats);
    EXPECT_EQ(set.load_selection(selection).size(), drawn);
    // Greedy to the end: no chunk could still move one level finer within the budget.
    for (size_t c = 0; c < set.chunks().size(); ++c) {
      const int level = selection.chunk_levels[c];
      if (level == 0) continue;
      const auto& levels = set.chunks()[c].levels;
      EXPECT_GT(selection.splats - levels[size_t(level)].count + levels[size_t(level - 1)].count, budget)
          << "chunk " << c << " could be finer at budget " << budget;
    }
    previous = selection.splats;
  }

  // Looking away: every chunk is out of view and nothing is drawn.
  tilesplat::Camera away = camera;
  for (size_t i = 0; i < 9; ++i) away.rotation[i] = -camera.rotation[i];
  for (size_t a = 0; a < 3; ++a) away.rotation[3 + a] = camera.rotation[3 + a];  // a proper rotation: y kept
  const LodSelection none = tilesplat::select_lod_levels(set, away, 10000);
  EXPECT_EQ(none.splats, 0u);
  EXPECT_TRUE(
      std::all_of(none.chunk_levels.begin(), none.chunk_levels.end(), [](int level) { return level == -1; }));
  EXPECT_TRUE(set.load_selection(none).empty());
}

// The renderer's own entry point draws what select_lod_levels and load_selection give, and level 0 whole
// without a budget; under a memory budget too (in parts, the same image).
TEST(LodSet, TheRendererDrawsTheLevelsTheBudgetChooses) {
  const LodSet set = LodSet::open(lod_index());
  const tilesplat::Camera camera = whole_view();
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  tilesplat::RenderSettings settings;
  settings.splat_budget = 6000;
  const tilesplat::RenderImage through_renderer = renderer.render(set, camera, settings);
  EXPECT_EQ(renderer.last_frame_stats().gaussians, tilesplat::select_lod_levels(set, camera, 6000).splats);
  const tilesplat::RenderImage by_hand =
      renderer.render(set.load_selection(tilesplat::select_lod_levels(set, camera, 6000)), camera, settings);
  EXPECT_EQ(through_renderer.rgba, by_hand.rgba);
  settings.memory_budget = 3 << 20;
  const tilesplat::RenderImage in_parts = renderer.render(set, camera, settings);
  EXPECT_GT(renderer.last_frame_stats().scene_parts, 1);
  EXPECT_EQ(in_parts.rgba, by_hand.rgba);

  const tilesplat::RenderImage finest = renderer.render(set, camera, tilesplat::RenderSettings{});
  EXPECT_EQ(renderer.last_frame_stats().gaussians, 31000u);
  EXPECT_EQ(finest.rgba, renderer.render(set.load_level(0), camera, tilesplat::RenderSettings{}).rgba);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// splat-transform's environment (the Gaussians it tags level -1) is drawn with every level and counts against
// the budget: a set whose environment is the shared playbot at its coarsest (1,873 Gaussians).
TEST(LodSet, TheEnvironmentIsDrawnWithEveryLevel) {
  const fs::path index =
      fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "lod_set_with_environment" / "lod-meta.json";
  const LodSet set = LodSet::open(index);
  EXPECT_EQ(set.levels(), 2);
  EXPECT_EQ(set.level_size(0), 64u);
  EXPECT_EQ(set.level_size(1), 32u);
  ASSERT_TRUE(set.environment().has_value());
  EXPECT_EQ(*set.environment(), "env/meta.json");
  EXPECT_EQ(set.environment_size(), 1873u);
  const tilesplat::GaussianScene environment =
      tilesplat::load_scene(index.parent_path() / "env" / "meta.json");
  for (int level = 0; level < 2; ++level) {
    const tilesplat::GaussianScene scene = set.load_level(level);
    ASSERT_EQ(scene.size(), set.level_size(level) + 1873u);
    // The environment comes last, as its file holds it (SH padded to the chunks' degree 3).
    const size_t first = set.level_size(level);
    EXPECT_TRUE(std::equal(environment.positions.begin(), environment.positions.end(),
                           scene.positions.begin() + std::ptrdiff_t(3 * first)));
    EXPECT_EQ(scene.sh_degree, 3);
  }
  // Framing the one chunk (the environment is elsewhere, and may be out of this view).
  ASSERT_EQ(set.chunks().size(), 1u);
  tilesplat::Bounds chunk;
  for (size_t a = 0; a < 3; ++a) {
    chunk.min[a] = set.chunks()[0].min[a];
    chunk.max[a] = set.chunks()[0].max[a];
    chunk.center[a] = 0.5 * (chunk.min[a] + chunk.max[a]);
    chunk.radius = std::max(chunk.radius, 0.5 * (chunk.max[a] - chunk.min[a]));
  }
  const tilesplat::Camera camera = tilesplat::orbit_camera(chunk, 160, 90);
  const LodSelection small = tilesplat::select_lod_levels(set, camera, 1000);
  EXPECT_TRUE(small.over_budget);  // the environment alone is 1,873
  EXPECT_EQ(small.splats, 32u + 1873u);
  const LodSelection large = tilesplat::select_lod_levels(set, camera, 5000);
  EXPECT_FALSE(large.over_budget);
  EXPECT_EQ(large.splats, 64u + 1873u);
  EXPECT_EQ(set.load_selection(large).size(), large.splats);
}

TEST(LodSet, KeepsDecodedChunkFilesWithinTheCacheLimit) {
  LodSet set = LodSet::open(lod_index());
  EXPECT_EQ(set.cached_bytes(), 0u);
  const tilesplat::GaussianScene first = set.load_level(1);
  EXPECT_GT(set.cached_bytes(), 0u);
  EXPECT_TRUE(same_scene(set.load_level(1), first));  // from the cache
  set.set_cache_bytes(0);
  EXPECT_EQ(set.cached_bytes(), 0u);
  EXPECT_TRUE(same_scene(set.load_level(1), first));  // read again
  EXPECT_EQ(set.cached_bytes(), 0u);
}

TEST(LodSet, AMalformedIndexIsAnErrorNamingTheFileAndTheValue) {
  const std::string name = lod_index().string();
  const auto expect_error = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& part) {
    const std::string error = parse_error(edit);
    EXPECT_TRUE(contains(error, name)) << part << ": " << error;
    EXPECT_TRUE(contains(error, part)) << error;
  };
  expect_error([](auto& j) { j["version"] = 2; }, "version 2 is not supported");
  expect_error([](auto& j) { j["lodLevels"] = 0; }, "lodLevels: must be at least 1");
  expect_error([](auto& j) { j["lodLevels"] = -1; }, "lodLevels: must be a whole number");
  expect_error([](auto& j) { j["lodLevels"] = 1000; }, "lodLevels: 1000 is out of range");
  expect_error([](auto& j) { j["counts"][1] = 7751; },
               "counts[1]: says 7751 Gaussians, and the tree's chunks hold 7750");
  expect_error([](auto& j) { j["counts"] = {1, 2}; }, "counts: must hold one count per level (3)");
  expect_error([](auto& j) { j["filenames"][0] = "../escape/meta.json"; }, "is not a path beside the index");
  expect_error([](auto& j) { j["filenames"][0] = 7; }, "filenames: holds a value that is not a file name");
  expect_error([](auto& j) { j.erase("tree"); }, "has no 'tree'");
  expect_error(
      [](auto& j) { first_leaf(j)["lods"]["0"]["file"] = 17; },
      "tree.children[0].children[0].children[0].children[0].children[0].lods.0.file: 17 is out of range");
  expect_error([](auto& j) { first_leaf(j)["lods"]["5"] = {}; }, "lods.5: not a level of the set (0 to 2)");
  expect_error([](auto& j) { first_leaf(j)["bound"]["min"][0] = 9; }, "bound: min is above max");
  expect_error([](auto& j) { first_leaf(j).erase("bound"); }, "a leaf (it has 'lods') needs 'bound'");
  expect_error([](auto& j) { first_leaf(j)["lods"]["1"]["count"] = 1.5; },
               "lods.1.count: must be a whole number");
  expect_error([](auto& j) { j["tree"]["children"] = 3; }, "tree.children: must be an array");
  expect_error([](auto& j) { j["environment"] = "/etc/passwd"; },
               "environment: must be the name of a file beside");
  expect_error(
      [](auto& j) {
        nlohmann::json deep = nlohmann::json::object();
        for (int i = 0; i < 200; ++i) deep = {{"children", {deep}}};
        j["tree"] = deep;
      },
      "the tree is deeper than 128 levels");
  try {
    LodSet::parse("{\"lodLevels\": 1, \"filenames\": [], \"tree\": ", lod_index());
    ADD_FAILURE() << "truncated JSON parsed";
  } catch (const SceneError& error) {
    EXPECT_TRUE(contains(error.what(), "not valid JSON")) << error.what();
  }
}

// A copy of the set in a temporary folder, for breaking its files.
fs::path copy_of_set(const fs::path& folder) {
  fs::remove_all(folder);
  fs::copy(lod_set_dir(), folder, fs::copy_options::recursive);
  return folder / "lod-meta.json";
}

TEST(LodSet, AMissingOrShortChunkFileIsAnErrorNamingIt) {
  const fs::path index = copy_of_set(tilesplat::testing::temp_dir() / "broken_set");
  fs::remove_all(index.parent_path() / "1_2");
  const LodSet set = LodSet::open(index);  // the index alone is fine
  EXPECT_NO_THROW(set.load_level(2));      // level 2 does not use 1_2
  try {
    set.load_level(1);
    ADD_FAILURE() << "a level with a missing chunk file loaded";
  } catch (const SceneError& error) {
    EXPECT_TRUE(contains(error.what(), index.string())) << error.what();
    EXPECT_TRUE(contains(error.what(), "the chunk file '1_2/meta.json' cannot be read")) << error.what();
  }

  // A slice past the end of its file.
  nlohmann::json json = nlohmann::json::parse(index_text());
  // The first leaf's level 2: Gaussians 0 to 64 of 2_0, moved to 1500 to 1564.
  first_leaf(json)["lods"]["2"]["offset"] = 1500;
  try {
    LodSet::parse(json.dump(), index).load_level(2);
    ADD_FAILURE() << "a slice past the end of its file loaded";
  } catch (const SceneError& error) {
    EXPECT_TRUE(contains(error.what(), "takes Gaussians 1500 to 1564 of '2_0/meta.json', which holds 1550"))
        << error.what();
  }

  // A chunk file that is the index itself is refused, not read forever.
  json = nlohmann::json::parse(index_text());
  json["filenames"][2] = "lod-meta.json";
  try {
    LodSet::parse(json.dump(), index).load_level(2);
    ADD_FAILURE() << "an index naming itself loaded";
  } catch (const SceneError& error) {
    EXPECT_TRUE(contains(error.what(), "is itself a LOD set index")) << error.what();
  }
}

// Several threads loading from one set (a LodStreamer's, a renderer's, the caller's) get what one thread
// gets, with a cache small enough that they evict one another's files.
TEST(LodSet, LoadsFromSeveralThreadsAtOnceAsFromOne) {
  LodSet set = LodSet::open(lod_index());
  std::vector<tilesplat::GaussianScene> levels;
  for (int level = 0; level < set.levels(); ++level) levels.push_back(set.load_level(level));
  set.set_cache_bytes(200000);  // about two chunk files of level 0
  std::vector<std::thread> threads;
  std::atomic<int> wrong = 0;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int round = 0; round < 6; ++round) {
        const int level = (t + round) % set.levels();
        if (!same_scene(set.load_level(level), levels[size_t(level)])) ++wrong;
      }
    });
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(wrong, 0);
  EXPECT_LE(set.cached_bytes(), 200000u);
}

// The camera `steps` of a tenth of the distance to the capture's centre closer than whole_view(): the
// chunks near it take finer levels as it nears them.
tilesplat::Camera dolly(int steps) {
  tilesplat::Camera camera = whole_view();
  const tilesplat::Bounds bounds =
      tilesplat::compute_bounds(tilesplat::load_ply(tilesplat::testing::bundled_playbot()));
  for (size_t a = 0; a < 3; ++a) camera.position[a] += 0.1 * steps * (bounds.center[a] - camera.position[a]);
  return camera;
}

TEST(LodStreamer, LoadsTheLevelsACameraCallsForOnItsThread) {
  const LodSet set = LodSet::open(lod_index());
  std::atomic<int> loads = 0;
  tilesplat::LodStreamer streamer(set, 10000, {}, [&loads] { ++loads; });
  EXPECT_EQ(streamer.splat_budget(), 10000u);
  EXPECT_FALSE(streamer.take());  // nothing asked for yet
  EXPECT_FALSE(streamer.wait_and_take());

  const LodSelection chosen = streamer.request(whole_view());
  const LodSelection expected = tilesplat::select_lod_levels(set, whole_view(), 10000);
  EXPECT_EQ(chosen.chunk_levels, expected.chunk_levels);
  EXPECT_EQ(chosen.splats, expected.splats);
  const std::optional<tilesplat::LodLoad> loaded = streamer.wait_and_take();
  ASSERT_TRUE(loaded);
  EXPECT_FALSE(streamer.busy());
  EXPECT_EQ(loads, 1);
  EXPECT_EQ(loaded->selection.chunk_levels, expected.chunk_levels);
  EXPECT_EQ(loaded->scene.size(), expected.splats);
  EXPECT_TRUE(same_scene(loaded->scene, set.load_selection(expected)));

  // The same levels again are no request: nothing is read, nothing comes.
  streamer.request(whole_view());
  EXPECT_FALSE(streamer.busy());
  EXPECT_FALSE(streamer.wait_and_take());
  EXPECT_EQ(loads, 1);
}

// A camera moving faster than its levels are read: the streamer is held inside its first load (its
// callback waits) while the camera moves on; the requests made meanwhile replace one another, and the next
// load is the newest camera's levels alone.
TEST(LodStreamer, OnlyTheNewestCamerasLevelsWaitToBeRead) {
  const LodSet set = LodSet::open(lod_index());
  std::atomic<int> loads = 0;
  std::latch first_load_held(1);
  tilesplat::LodStreamer streamer(set, 6000, {}, [&] {
    if (++loads == 1) first_load_held.wait();
  });
  streamer.request(dolly(0));
  while (loads == 0) std::this_thread::yield();  // the first load is done, its callback waits

  std::vector<int> previous = tilesplat::select_lod_levels(set, dolly(0), 6000).chunk_levels;
  int changes = 0;
  for (int step = 1; step < 8; ++step) {
    const LodSelection chosen = streamer.request(dolly(step));
    if (chosen.chunk_levels != previous) ++changes;
    previous = chosen.chunk_levels;
  }
  ASSERT_GE(changes, 3) << "the path should change the levels";
  EXPECT_TRUE(streamer.busy());
  const std::optional<tilesplat::LodLoad> first = streamer.take();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->selection.chunk_levels, tilesplat::select_lod_levels(set, dolly(0), 6000).chunk_levels);

  first_load_held.count_down();
  const std::optional<tilesplat::LodLoad> last = streamer.wait_and_take();
  ASSERT_TRUE(last);
  const LodSelection expected = tilesplat::select_lod_levels(set, dolly(7), 6000);
  EXPECT_EQ(last->selection.chunk_levels, expected.chunk_levels);
  EXPECT_TRUE(same_scene(last->scene, set.load_selection(expected)));
  EXPECT_EQ(loads, 2);  // the first camera's and the newest's: none of the steps between
}

// A load that fails is rethrown once, naming the file; the same levels can then be asked for again.
TEST(LodStreamer, AFailedLoadIsRethrownAndCanBeAskedForAgain) {
  const fs::path index = copy_of_set(tilesplat::testing::temp_dir() / "streamed_broken_set");
  fs::remove_all(index.parent_path() / "0_0");
  const LodSet set = LodSet::open(index);
  tilesplat::LodStreamer streamer(set, 1000000);  // every chunk at level 0
  for (int attempt = 0; attempt < 2; ++attempt) {
    streamer.request(whole_view());
    try {
      streamer.wait_and_take();
      ADD_FAILURE() << "a level with a missing chunk file loaded";
    } catch (const SceneError& error) {
      EXPECT_TRUE(contains(error.what(), "the chunk file '0_0/meta.json' cannot be read")) << error.what();
    }
    EXPECT_FALSE(streamer.take());  // rethrown once
  }
  // Destroyed while a load runs: the destructor waits for it.
  tilesplat::LodStreamer(set, 2000).request(whole_view());
}

TEST(LodSetCli, RendersALevelOrASplatBudgetAndTellsWhatItDrew) {
  const fs::path out = fresh_output_dir();
  const auto render = [&](const std::vector<std::string>& extra, const std::string& name) {
    std::vector<std::string> args = {lod_index().string(),
                                     "--cameras",
                                     tilesplat::testing::bundled_playbot_cameras().string(),
                                     "--width",
                                     "160",
                                     "-o",
                                     (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_process(TILESPLAT_RENDER_EXE, args);
  };
  const auto level0 = render({}, "level0.exr");
  ASSERT_EQ(level0.exit_code, 0) << level0.err;
  EXPECT_TRUE(contains(level0.err, "LOD set of 3 levels (31,000 / 7,750 / 1,550 Gaussians), level 0"))
      << level0.err;
  const auto all = render({"--splat-budget", "100000", "--stats"}, "budget_all.exr");
  ASSERT_EQ(all.exit_code, 0) << all.err;
  EXPECT_TRUE(contains(all.out, "lod splats                      31000")) << all.out;
  EXPECT_EQ(tilesplat::read_exr(out / "budget_all.exr").rgba, tilesplat::read_exr(out / "level0.exr").rgba);

  const auto some = render({"--splat-budget", "10000", "--stats"}, "budget_10k.exr");
  ASSERT_EQ(some.exit_code, 0) << some.err;
  EXPECT_TRUE(contains(some.out, "lod 0 chunks")) << some.out;
  const auto level2 = render({"--lod", "2"}, "level2.exr");
  ASSERT_EQ(level2.exit_code, 0) << level2.err;
  // The budget's image lies between the coarsest level's and the finest's.
  const tilesplat::RenderImage finest = tilesplat::read_exr(out / "level0.exr");
  const double budget_psnr =
      tilesplat::compare_images(finest, tilesplat::read_exr(out / "budget_10k.exr")).psnr_db;
  const double coarsest_psnr =
      tilesplat::compare_images(finest, tilesplat::read_exr(out / "level2.exr")).psnr_db;
  EXPECT_GT(budget_psnr, coarsest_psnr);
  EXPECT_LT(budget_psnr, 100.0);

  const auto low = render({"--splat-budget", "100"}, "low.exr");
  EXPECT_EQ(low.exit_code, 0) << low.err;
  EXPECT_TRUE(
      contains(low.err, "--splat-budget 100 is below what the coarsest levels in view draw (1550 Gaussians)"))
      << low.err;

  const auto no_level = render({"--lod", "3"}, "no_level.exr");
  EXPECT_NE(no_level.exit_code, 0);
  EXPECT_TRUE(contains(no_level.err, "there is no level 3 (the set has levels 0 to 2)")) << no_level.err;
  const auto not_a_set =
      run_process(TILESPLAT_RENDER_EXE, {tilesplat::testing::bundled_playbot().string(), "--lod", "1",
                                         "--width", "64", "-o", (out / "ply.exr").string()});
  EXPECT_EQ(not_a_set.exit_code, 2);
  EXPECT_TRUE(contains(not_a_set.err, "--lod needs a LOD set (lod-meta.json)")) << not_a_set.err;
  const auto both = render({"--lod", "1", "--splat-budget", "5000"}, "both.exr");
  EXPECT_EQ(both.exit_code, 2);
  for (const char* name : {"no_level.exr", "ply.exr", "both.exr"})
    EXPECT_FALSE(fs::exists(out / name)) << name;
}

// A camera path under a splat budget: each frame's levels are read on a thread while the frame before
// renders; every frame is still the renderer's frame of its own camera's levels.
TEST(LodSetCli, ACameraPathDrawsEachFramesOwnLevels) {
  const fs::path out = fresh_output_dir();
  const auto rendered = run_process(
      TILESPLAT_RENDER_EXE, {lod_index().string(), "--orbit", "6", "--elevation", "20", "--width", "160",
                             "--height", "90", "--splat-budget", "6000", "-o", (out / "%02d.exr").string()});
  ASSERT_EQ(rendered.exit_code, 0) << rendered.err;
  const LodSet set = LodSet::open(lod_index());
  const std::unique_ptr<tilesplat::Renderer> renderer = tilesplat::Renderer::create();
  tilesplat::RenderSettings settings;
  settings.splat_budget = 6000;
  std::vector<std::vector<int>> levels;
  for (int frame = 0; frame < 6; ++frame) {
    const fs::path exr = out / (std::string(frame < 10 ? "0" : "") + std::to_string(frame) + ".exr");
    const std::optional<tilesplat::Camera> camera = tilesplat::read_exr_camera(exr);
    ASSERT_TRUE(camera) << exr;
    const tilesplat::ImageDifference difference =
        tilesplat::compare_images(tilesplat::read_exr(exr), renderer->render(set, *camera, settings));
    // The same levels: the same image to float rounding (the app's EXR against the library's frame).
    EXPECT_GE(difference.psnr_db, 100.0) << exr << ": max abs " << difference.max_abs;
    const std::vector<int> chosen = tilesplat::select_lod_levels(set, *camera, 6000).chunk_levels;
    if (std::find(levels.begin(), levels.end(), chosen) == levels.end()) levels.push_back(chosen);
  }
  EXPECT_GE(levels.size(), 3u) << "the orbit should change the levels";
}

TEST(LodSetCli, InfoListsTheLevels) {
  const auto text = run_process(TILESPLAT_INFO_EXE, {lod_index().string()});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_TRUE(
      contains(text.out, "lod set      3 levels, 42 chunks, 17 chunk files, made by splat-transform v3.7.0"))
      << text.out;
  EXPECT_TRUE(contains(text.out, "level 1      7,750 Gaussians in 42 chunks, 4 files")) << text.out;
  const auto json = run_process(TILESPLAT_INFO_EXE, {"--json", lod_index().string()});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json info = nlohmann::json::parse(json.out).at(0);
  EXPECT_EQ(info.at("lod_levels").size(), 3u);
  EXPECT_EQ(info.at("lod_levels")[2].at("gaussians"), 1550);
  EXPECT_EQ(info.at("gaussians"), 31000);
}

TEST(LodSetCli, BenchDrawsTheCurveOfLevelsAndBudgets) {
  const fs::path out = fresh_output_dir();
  const auto run = run_process(
      TILESPLAT_BENCH_EXE,
      {lod_index().string(), "--cameras", tilesplat::testing::bundled_playbot_cameras().string(), "--views",
       "0,4", "--width", "160", "--lod-curve", "40000,3000", "--warmup", "0", "--repeat", "1", "--csv",
       (out / "lod.csv").string(), "--plot", (out / "lod.svg").string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* row : {"level 0", "level 1", "level 2", "budget 3,000", "budget 40,000"})
    EXPECT_TRUE(contains(run.out, row)) << row << "\n" << run.out;
  const std::string csv = tilesplat::testing::read_file(out / "lod.csv");
  // Level 0 and a budget above it are level 0's image; the budget of 3,000 lies between levels 2 and 1.
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(csv);  // header, levels 0 1 2, budgets 3,000 and 40,000
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> fields(1);
    bool quoted = false;  // the device's name is quoted and has commas
    for (const char c : line) {
      if (c == '"')
        quoted = !quoted;
      else if (c == ',' && !quoted)
        fields.emplace_back();
      else
        fields.back() += c;
    }
    rows.push_back(fields);
  }
  ASSERT_GE(rows.size(), 6u) << csv;
  EXPECT_EQ(rows[0][2], "level");
  EXPECT_EQ(rows[1][7], "inf") << csv;  // level 0
  EXPECT_EQ(rows[5][3], "40000");
  EXPECT_EQ(rows[5][7], "inf") << csv;  // budget 40,000: every chunk at level 0
  EXPECT_EQ(rows[4][3], "3000");
  EXPECT_LE(std::stod(rows[4][4]), 3000.0) << csv;                 // splats within the budget
  EXPECT_GT(std::stod(rows[4][7]), std::stod(rows[3][7])) << csv;  // sharper than level 2 whole
  EXPECT_TRUE(contains(tilesplat::testing::read_file(out / "lod.svg"), "splat budgets"));

  const auto not_a_set = run_process(TILESPLAT_BENCH_EXE, {tilesplat::testing::bundled_playbot().string(),
                                                           "--width", "64", "--lod-curve", "1000"});
  EXPECT_EQ(not_a_set.exit_code, 2);
  EXPECT_TRUE(contains(not_a_set.err, "--lod-curve measures a LOD set (lod-meta.json)")) << not_a_set.err;
}

}  // namespace
