// tilesplat-render with many frames in one process: views, orbits and paths bit-identical to single
// renders, the manifest that makes a killed run resumable, shards merged back into one run, and the
// mistakes it refuses before rendering anything.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "cli.h"
#include "frame_manifest.h"
#include "process_support.h"
#include "progress.h"
#include "test_support.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
namespace cli = tilesplat::cli;
using tilesplat::testing::expect_one_error_line;
using tilesplat::testing::fresh_output_dir;
using tilesplat::testing::ProcessResult;
using tilesplat::testing::read_file;
using tilesplat::testing::run_process;

constexpr const char* kRenderExe = TILESPLAT_RENDER_EXE;

ProcessResult render(const std::vector<std::string>& args) {
  return run_process("", kRenderExe, args);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

fs::path small_scene() {
  return tilesplat::testing::shared_scenes() / "playbot_lod6_1873_sh2.ply";
}
fs::path small_cameras() {
  return tilesplat::testing::shared_scenes() / "cameras" / "playbot_lod6_1873_sh2.json";
}

// Pixels, depth and splat counts equal bit for bit.
void expect_same_image(const fs::path& a, const fs::path& b) {
  const tilesplat::RenderImage first = tilesplat::read_exr(a), second = tilesplat::read_exr(b);
  EXPECT_EQ(first.width, second.width) << a << " vs " << b;
  EXPECT_EQ(first.height, second.height) << a << " vs " << b;
  EXPECT_TRUE(first.rgba == second.rgba) << a << " vs " << b;
  EXPECT_TRUE(first.depth == second.depth) << a << " vs " << b;
  EXPECT_TRUE(first.splat_count == second.splat_count) << a << " vs " << b;
}

std::vector<cli::ManifestEntry> manifest_entries(const fs::path& folder) {
  std::vector<cli::ManifestEntry> entries;
  for (const cli::ManifestLine& line : cli::read_manifests(folder)) entries.push_back(line.entry);
  return entries;
}

// How many times each frame appears in the folder's manifests.
std::map<int, int> frame_counts(const fs::path& folder) {
  std::map<int, int> counts;
  for (const cli::ManifestEntry& entry : manifest_entries(folder)) ++counts[entry.frame];
  return counts;
}

TEST(RenderSequence, AllViewsInOneProcessEqualSingleViewRenders) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path out = fresh_output_dir();
  const auto all = render({small_scene().string(), "--cameras", small_cameras().string(), "--views", "all",
                           "--width", "480", "--height", "270", "-o", (out / "view_%04d.exr").string(),
                           "--png", (out / "view_%04d.png").string()});
  ASSERT_EQ(all.exit_code, 0) << all.err;
  EXPECT_TRUE(contains(all.err, "8 frames rendered")) << all.err;
  // stderr is not a terminal here: progress comes as plain lines (at least the last one), no bar.
  EXPECT_TRUE(contains(all.err, "tilesplat-render: 8/8 frames, ")) << all.err;
  EXPECT_FALSE(contains(all.err, "\r")) << all.err;
  const auto entries = manifest_entries(out);
  ASSERT_EQ(entries.size(), 8u);
  for (int view = 0; view < 8; ++view) {
    char name[32];
    std::snprintf(name, sizeof name, "view_%04d.exr", view);
    const fs::path single = out / ("single_" + std::to_string(view) + ".exr");
    const auto one =
        render({small_scene().string(), "--cameras", small_cameras().string(), "--view", std::to_string(view),
                "--width", "480", "--height", "270", "-o", single.string()});
    ASSERT_EQ(one.exit_code, 0) << one.err;
    expect_same_image(out / name, single);
    EXPECT_EQ(tilesplat::read_exr_string_attributes(out / name).at("viewIndex"), std::to_string(view));
    EXPECT_EQ(tilesplat::read_exr_camera(out / name), tilesplat::read_exr_camera(single));
    // The manifest line names the file with its size and checksum.
    const cli::ManifestEntry& entry = entries[size_t(view)];
    EXPECT_EQ(entry.frame, view);
    EXPECT_EQ(entry.number, view);
    EXPECT_EQ(entry.file, name);
    EXPECT_EQ(entry.bytes, fs::file_size(out / name));
    EXPECT_TRUE(cli::files_match(out, entry));
    EXPECT_TRUE(fs::exists(out / entry.png));
  }
  // every:K and lists pick views by their index, which is the number in the file name.
  const fs::path picked = out / "picked";
  fs::create_directories(picked);
  const auto some = render({small_scene().string(), "--cameras", small_cameras().string(), "--views",
                            "every:3", "--width", "480", "-o", (picked / "v%d.exr").string(), "--quiet"});
  ASSERT_EQ(some.exit_code, 0) << some.err;
  EXPECT_EQ(some.err, "");
  for (const int view : {0, 3, 6})
    expect_same_image(picked / ("v" + std::to_string(view) + ".exr"),
                      out / ("view_000" + std::to_string(view) + ".exr"));
  EXPECT_EQ(manifest_entries(picked).size(), 3u);
}

TEST(RenderSequence, OrbitAndPathFramesEqualRendersOfTheirCameras) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path out = fresh_output_dir();
  const fs::path keys = out / "keys.json";
  std::ofstream(keys) << R"({"keyframes": [
    {"position": [0, -1, 4], "look_at": [0, 0, 0], "fov": 50},
    {"position": [3, -1, 2], "rotation": [[0.6, 0, -0.8], [0, 1, 0], [0.8, 0, 0.6]], "fov": 40},
    {"position": [2, -2, -3], "look_at": [0, 0, 0], "up": [0, -1, 0]}
  ]})";
  const auto orbit = render({small_scene().string(), "--orbit", "4", "--elevation", "30", "--width", "240",
                             "--height", "135", "-o", (out / "orbit_%02d.exr").string()});
  ASSERT_EQ(orbit.exit_code, 0) << orbit.err;
  const auto path = render({small_scene().string(), "--path", keys.string(), "--frames", "5", "--width",
                            "240", "--height", "135", "-o", (out / "path_%02d.exr").string()});
  ASSERT_EQ(path.exit_code, 0) << path.err;

  const tilesplat::GaussianScene scene = tilesplat::load_scene(small_scene());
  tilesplat::OrbitParams params;
  params.elevation_deg = 30;
  const auto orbit_cameras = tilesplat::orbit_cameras(scene, 4, 240, 135, params);
  const auto path_cameras = tilesplat::sample_camera_path(tilesplat::load_camera_path(keys), 5, 240, 135);
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(scene);
  auto expect_frame = [&](const fs::path& file, const tilesplat::Camera& camera) {
    EXPECT_EQ(tilesplat::read_exr_camera(file), camera) << file;
    tilesplat::RenderImage expected = renderer.render(camera);
    // The files put empty pixels far away (tilesplat::kFarDepth) for depth compositing.
    size_t empty = 0;
    for (size_t i = 0; i < expected.pixels(); ++i)
      if (expected.rgba[4 * i + 3] == 0.0f) {
        EXPECT_EQ(expected.depth[i], 0.0f);
        expected.depth[i] = tilesplat::kFarDepth;
        ++empty;
      }
    EXPECT_GT(empty, 0u) << file << " shows no background: the test checks nothing of empty pixels";
    const tilesplat::RenderImage written = tilesplat::read_exr(file);
    // Scene-linear in the file, encoded back by read_exr: equal to float rounding.
    EXPECT_LE(tilesplat::compare_images(expected, written).max_abs, 1e-6) << file;
    EXPECT_EQ(tilesplat::compare_images(expected, written).max_abs_alpha, 0.0) << file;
    EXPECT_TRUE(expected.depth == written.depth) << file;
  };
  for (int f = 0; f < 4; ++f)
    expect_frame(out / ("orbit_0" + std::to_string(f) + ".exr"), orbit_cameras[size_t(f)]);
  for (int f = 0; f < 5; ++f)
    expect_frame(out / ("path_0" + std::to_string(f) + ".exr"), path_cameras[size_t(f)]);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// Starts tilesplat-render without waiting; its output goes to `log`.
pid_t start_render(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv = {kRenderExe};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> pointers;
  for (std::string& arg : argv) pointers.push_back(arg.data());
  pointers.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, kRenderExe, &actions, nullptr, pointers.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

TEST(RenderSequence, KilledRunResumesWithEveryFrameOnceAndBitIdentical) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path root = fresh_output_dir();
  const fs::path whole = root / "whole", resumed = root / "resumed";
  fs::create_directories(whole);
  fs::create_directories(resumed);
  const std::string scene = (tilesplat::testing::shared_scenes() / "playbot_lod3_31000_sh2.ply").string();
  auto args = [&](const fs::path& folder) {
    return std::vector<std::string>{
        scene, "--orbit", "16", "--width", "320", "--height", "180", "-o", (folder / "f_%03d.exr").string()};
  };
  const auto uninterrupted = render(args(whole));
  ASSERT_EQ(uninterrupted.exit_code, 0) << uninterrupted.err;

  // Kill a run once a few frames are in its manifest.
  const pid_t pid = start_render(args(resumed), root / "killed.log");
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  size_t finished = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    finished = fs::exists(resumed / "manifest.jsonl") ? manifest_entries(resumed).size() : 0;
    if (finished >= 3) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_GE(finished, 3u) << read_file(root / "killed.log");
  const size_t done_at_kill = manifest_entries(resumed).size();
  ASSERT_LT(done_at_kill, 16u) << "the run finished before it was killed: nothing to resume";
  // Whatever the kill left, every file in the folder is either complete or not an EXR name.
  for (const auto& item : fs::directory_iterator(resumed)) {
    const std::string name = item.path().filename().string();
    if (name.starts_with("f_")) {
      EXPECT_NO_THROW(tilesplat::read_exr(item.path())) << name;
    }
  }

  const auto again = render(args(resumed));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(contains(again.err, std::to_string(done_at_kill) + " already done")) << again.err;
  EXPECT_TRUE(contains(again.err, std::to_string(16 - done_at_kill) + " frames rendered")) << again.err;
  const auto counts = frame_counts(resumed);
  ASSERT_EQ(counts.size(), 16u);
  for (const auto& [frame, count] : counts) EXPECT_EQ(count, 1) << "frame " << frame;
  for (int f = 0; f < 16; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "f_%03d.exr", f);
    expect_same_image(resumed / name, whole / name);
  }

  // A damaged file fails its checksum and is rendered again; the rest are skipped.
  {
    std::fstream file(resumed / "f_005.exr", std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(fs::file_size(resumed / "f_005.exr") / 2));
    file.put('\x5a');
  }
  const auto repaired = render(args(resumed));
  ASSERT_EQ(repaired.exit_code, 0) << repaired.err;
  EXPECT_TRUE(contains(repaired.err, "15 already done")) << repaired.err;
  EXPECT_TRUE(contains(repaired.err, "1 frames rendered")) << repaired.err;
  expect_same_image(resumed / "f_005.exr", whole / "f_005.exr");
  // --force renders everything again.
  const auto forced = render([&] {
    auto a = args(resumed);
    a.push_back("--force");
    return a;
  }());
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_TRUE(contains(forced.err, "16 frames rendered")) << forced.err;
}

TEST(RenderSequence, FourShardsMergeIntoTheUnshardedRun) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path root = fresh_output_dir();
  const fs::path whole = root / "whole", sharded = root / "sharded";
  fs::create_directories(whole);
  fs::create_directories(sharded);
  auto args = [&](const fs::path& folder) {
    return std::vector<std::string>{small_scene().string(),
                                    "--cameras",
                                    small_cameras().string(),
                                    "--views",
                                    "all",
                                    "--width",
                                    "160",
                                    "-o",
                                    (folder / "v_%02d.exr").string()};
  };
  ASSERT_EQ(render(args(whole)).exit_code, 0);

  for (int shard = 0; shard < 4; ++shard) {
    auto shard_args = args(sharded);
    shard_args.insert(shard_args.end(), {"--shard", std::to_string(shard) + "/4"});
    const auto result = render(shard_args);
    ASSERT_EQ(result.exit_code, 0) << result.err;
    EXPECT_TRUE(contains(result.err, "shard " + std::to_string(shard) + "/4 (--shard): 2 of 8 frames"))
        << result.err;
    ASSERT_TRUE(fs::exists(sharded / ("manifest.shard-" + std::to_string(shard) + "-of-4.jsonl")));
    if (shard == 2) {  // before the last shard ran, the merge names what is missing
      const auto early = render({"--merge-manifests", sharded.string()});
      EXPECT_EQ(early.exit_code, 1);
      EXPECT_TRUE(contains(early.err, "2 of 8 frames are in no manifest: 3, 7")) << early.err;
    }
  }
  const auto merged = render({"--merge-manifests", sharded.string()});
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_TRUE(contains(merged.err, "4 shard manifests cover all 8 frames exactly once")) << merged.err;
  std::vector<cli::ManifestEntry> union_entries;
  for (const cli::ManifestLine& line : cli::read_manifests(sharded))
    if (line.manifest.filename() == "manifest.jsonl") union_entries.push_back(line.entry);
  ASSERT_EQ(union_entries.size(), 8u);
  for (int f = 0; f < 8; ++f) {
    EXPECT_EQ(union_entries[size_t(f)].frame, f);
    char name[16];
    std::snprintf(name, sizeof name, "v_%02d.exr", f);
    expect_same_image(sharded / name, whole / name);
  }

  // A shard's damaged file is named by the merge.
  {
    std::fstream file(sharded / "v_06.exr", std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(100);
    file.put('\x01');
  }
  const auto damaged = render({"--merge-manifests", sharded.string()});
  EXPECT_EQ(damaged.exit_code, 1);
  EXPECT_TRUE(contains(damaged.err, "do not match their manifest's checksum: 6")) << damaged.err;
}

TEST(RenderSequence, ExrIsValidPremultipliedOverABackgroundAndEmptyPixelsAreFar) {
  const fs::path out = fresh_output_dir();
  const std::string scene = tilesplat::testing::bundled_sh3().string();
  for (const char* background : {"0,0,0", "1,0.5,0.25"}) {
    const fs::path exr = out / (std::string(background) + ".exr");
    const auto result =
        render({scene, "--width", "64", "--height", "36", "--background", background, "-o", exr.string()});
    ASSERT_EQ(result.exit_code, 0) << result.err;
  }
  const tilesplat::RenderImage black = tilesplat::read_exr(out / "0,0,0.exr");
  const tilesplat::RenderImage coloured = tilesplat::read_exr(out / "1,0.5,0.25.exr");
  size_t empty = 0, partial = 0;
  for (size_t i = 0; i < black.pixels(); ++i) {
    const float alpha = black.rgba[4 * i + 3];
    if (alpha == 0.0f) {
      ++empty;
      EXPECT_EQ(black.depth[i], tilesplat::kFarDepth) << "pixel " << i;
      EXPECT_EQ(coloured.rgba[4 * i + 0], 1.0f);  // the background alone
    } else {
      EXPECT_LT(black.depth[i], 1e3f) << "pixel " << i;
    }
    if (alpha > 0.0f && alpha < 1.0f) ++partial;
    // Over black: R G B are the splats' premultiplied colours; over a colour, the frame is opaque
    // and R G B hold the background where the splats let it through.
    EXPECT_EQ(coloured.rgba[4 * i + 3], 1.0f) << "pixel " << i;
    EXPECT_NEAR(coloured.rgba[4 * i + 0], black.rgba[4 * i + 0] + (1 - alpha) * 1.0f, 1e-6) << "pixel " << i;
  }
  EXPECT_GT(empty, 0u);
  EXPECT_GT(partial, 0u);
}

TEST(RenderSequence, ShardComesFromSlurmOrAnIndexedJob) {
  auto environment = [](std::map<std::string, std::string> variables) {
    return [variables](const char* name) -> std::optional<std::string> {
      const auto found = variables.find(name);
      if (found == variables.end()) return std::nullopt;
      return found->second;
    };
  };
  const cli::Shard slurm = cli::resolve_shard(
      std::nullopt, std::nullopt,
      environment(
          {{"SLURM_ARRAY_TASK_ID", "3"}, {"SLURM_ARRAY_TASK_MIN", "1"}, {"SLURM_ARRAY_TASK_COUNT", "4"}}));
  EXPECT_EQ(slurm.index, 2);
  EXPECT_EQ(slurm.count, 4);
  EXPECT_EQ(slurm.source, "SLURM_ARRAY_TASK_ID=3");
  EXPECT_TRUE(slurm.takes(6));
  EXPECT_FALSE(slurm.takes(7));
  const cli::Shard indexed =
      cli::resolve_shard(std::nullopt, std::nullopt,
                         environment({{"JOB_COMPLETION_INDEX", "1"}, {"TILESPLAT_SHARD_COUNT", "3"}}));
  EXPECT_EQ(indexed.index, 1);
  EXPECT_EQ(indexed.count, 3);
  EXPECT_EQ(cli::resolve_shard(std::nullopt, 5, environment({{"JOB_COMPLETION_INDEX", "4"}})).count, 5);
  // The flag wins over the environment.
  EXPECT_EQ(cli::resolve_shard("0/2", std::nullopt, environment({{"SLURM_ARRAY_TASK_ID", "1"}})).count, 2);
  EXPECT_EQ(cli::resolve_shard(std::nullopt, std::nullopt, environment({})).count, 1);
  EXPECT_THROW(cli::resolve_shard(std::nullopt, std::nullopt, environment({{"JOB_COMPLETION_INDEX", "1"}})),
               cli::UsageError);
  EXPECT_THROW(
      cli::resolve_shard(std::nullopt, std::nullopt,
                         environment({{"SLURM_ARRAY_TASK_ID", "4"}, {"SLURM_ARRAY_TASK_COUNT", "4"}})),
      cli::UsageError);
  EXPECT_THROW(cli::resolve_shard("3", std::nullopt, environment({})), cli::UsageError);
  EXPECT_THROW(cli::resolve_shard("1/0", std::nullopt, environment({})), cli::UsageError);
}

TEST(RenderSequence, ViewSelectionsAndFramePatterns) {
  EXPECT_EQ(cli::parse_view_selection("--views", "all", 3), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(cli::parse_view_selection("--views", "every:8", 20), (std::vector<int>{0, 8, 16}));
  EXPECT_EQ(cli::parse_view_selection("--views", "5,0,2-4", 6), (std::vector<int>{5, 0, 2, 3, 4}));
  EXPECT_THROW(cli::parse_view_selection("--views", "6", 6), cli::UsageError);
  EXPECT_THROW(cli::parse_view_selection("--views", "every:0", 6), cli::UsageError);
  EXPECT_THROW(cli::parse_view_selection("--views", "1,,2", 6), cli::UsageError);
  EXPECT_EQ(cli::frame_file("-o", "out/view_%04d.exr", 12), "out/view_0012.exr");
  EXPECT_EQ(cli::frame_file("-o", "a%db", 123), "a123b");
  EXPECT_EQ(cli::frame_file("-o", "100%%_%3d.exr", 7), "100%_  7.exr");
  EXPECT_EQ(cli::frame_file("-o", "plain.exr", 7), "plain.exr");
  EXPECT_FALSE(cli::has_frame_number("100%%.exr"));
  EXPECT_THROW(cli::frame_file("-o", "a_%s.exr", 1), cli::UsageError);
  EXPECT_THROW(cli::frame_file("-o", "a_%d_%d.exr", 1), cli::UsageError);
  EXPECT_EQ(cli::describe_frames({9, 1, 2, 3, 7}), "1-3, 7, 9");
}

TEST(RenderSequence, ProgressSaysFramesRateAndTimeLeft) {
  EXPECT_EQ(cli::format_duration(17.4), "17 s");
  EXPECT_EQ(cli::format_duration(62), "1:02");
  EXPECT_EQ(cli::format_duration(3723), "1:02:03");
  cli::FrameProgress progress("tilesplat-render", 4, cli::FrameProgress::Style::kQuiet);
  EXPECT_EQ(progress.status(), "0/4 frames");
  progress.frame_done();
  const std::string status = progress.status();
  EXPECT_TRUE(status.starts_with("1/4 frames, ")) << status;
  EXPECT_TRUE(contains(status, " frames/s, ETA ")) << status;
  for (int f = 0; f < 3; ++f) progress.frame_done();
  EXPECT_FALSE(contains(progress.status(), "ETA")) << progress.status();
}

TEST(RenderSequence, MistakesFailBeforeAnyFrameIsRendered) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path out = fresh_output_dir();
  const fs::path one_key = out / "one_key.json";
  std::ofstream(one_key) << R"({"keyframes": [{"position": [0, 0, 4], "look_at": [0, 0, 0]}]})";
  std::ofstream(out / "a_file") << "not a folder";
  const std::string scene = small_scene().string(), cameras = small_cameras().string();
  const std::string pattern = (out / "v_%02d.exr").string();
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{scene, "--cameras", cameras, "--views", "0,9", "-o", pattern},
       2,
       "there is no view 9: the cameras have 8"},
      {{scene, "--cameras", cameras, "--views", "all", "-o", (out / "v.exr").string()},
       2,
       "has no frame number for the 8 frames"},
      {{scene, "--cameras", cameras, "--views", "all", "--shard", "4/4", "-o", pattern},
       2,
       "shard index 4 is out of range for 4 shards"},
      {{scene, "--orbit", "3", "-o", (out / "a_file" / "o_%d.exr").string()}, 1, "is not a directory"},
      {{scene, "--path", one_key.string(), "--frames", "4", "-o", pattern},
       1,
       "a camera path needs at least 2 keyframes, found 1"},
      {{scene, "--path", one_key.string(), "-o", pattern}, 2, "--path needs --frames N"},
      {{scene, "--orbit", "3", "--views", "all", "-o", pattern}, 2, "give one of them"},
      {{scene, "--shard", "0/2", "-o", (out / "v.exr").string()}, 2, "--shard applies to many frames"},
  };
  for (const Case& c : cases) {
    const auto result = render(c.args);
    EXPECT_EQ(result.exit_code, c.exit_code) << result.err;
    expect_one_error_line(result, "tilesplat-render");
    EXPECT_TRUE(contains(result.err, c.message)) << result.err;
  }
  // A device that cannot be created fails before the manifest is opened.
  const auto no_device =
      run_process("env TILESPLAT_DEVICE=no-such-device ", kRenderExe, {scene, "--orbit", "2", "-o", pattern});
  EXPECT_EQ(no_device.exit_code, 1) << no_device.err;
  EXPECT_TRUE(contains(no_device.err, "no Vulkan device matches 'no-such-device'")) << no_device.err;
  // Nothing was written: no frame, no manifest.
  std::vector<std::string> left;
  for (const auto& item : fs::directory_iterator(out)) left.push_back(item.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"a_file", "one_key.json"}));
}

// A resume skips only frames whose manifest line matches what the run would write now: a changed
// size, camera, setting or EXR encoding renders every frame again (render_main.cpp's comparison of
// file, camera, size and settings), and the same arguments once more skip them all.
TEST(RenderSequence, ResumeRendersAgainWhatChangedAndSkipsWhatDidNot) {
  const fs::path out = fresh_output_dir();
  const std::string scene = tilesplat::testing::bundled_playbot().string();
  const std::string pattern = (out / "o_%02d.exr").string();
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {scene, "--orbit", "4", "--width", "64", "--height", "36", "-o", pattern};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto result = render(args);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    return result.err;
  };
  auto expect_rendered_all = [&](const std::string& err, const std::string& what) {
    EXPECT_TRUE(contains(err, "4 frames rendered")) << what << ": " << err;
    EXPECT_FALSE(contains(err, "already done")) << what << ": " << err;
  };
  expect_rendered_all(run({}), "the first run");
  const std::string again = run({});
  EXPECT_TRUE(contains(again, "4 already done")) << again;
  EXPECT_TRUE(contains(again, "0 frames rendered")) << again;
  expect_rendered_all(run({"--width", "96", "--height", "54"}), "another size");
  EXPECT_EQ(tilesplat::read_exr(out / "o_02.exr").width, 96);
  expect_rendered_all(run({"--width", "96", "--height", "54", "--elevation", "35"}), "other cameras");
  expect_rendered_all(run({"--width", "96", "--height", "54", "--elevation", "35", "--mode", "depth16"}),
                      "another accuracy mode");
  expect_rendered_all(run({"--width", "96", "--height", "54", "--elevation", "35", "--mode", "depth16",
                           "--exr-colour", "display"}),
                      "another EXR encoding");
  EXPECT_EQ(tilesplat::read_exr_string_attributes(out / "o_03.exr").at("colorInteropID"),
            "srgb_rec709_display");
  const std::string last = run({"--width", "96", "--height", "54", "--elevation", "35", "--mode", "depth16",
                                "--exr-colour", "display"});
  EXPECT_TRUE(contains(last, "4 already done")) << last;
  // Each frame's newest line describes the files now in the folder.
  std::map<int, cli::ManifestEntry> newest;
  for (const cli::ManifestEntry& entry : manifest_entries(out)) newest[entry.frame] = entry;
  ASSERT_EQ(newest.size(), 4u);
  for (const auto& [frame, entry] : newest) {
    EXPECT_EQ(entry.width, 96) << frame;
    EXPECT_TRUE(cli::files_match(out, entry)) << frame;
  }
}

// A run killed while writing leaves a torn last line: the next run ignores it, cuts it off before it
// appends, and leaves a manifest whose every line parses. A complete line that is not an entry is an
// error naming the manifest and the line, before anything is rendered.
TEST(RenderSequence, TornManifestLineIsCutOffAndMalformedLineIsNamed) {
  const fs::path out = fresh_output_dir();
  const std::vector<std::string> args = {tilesplat::testing::bundled_playbot().string(),
                                         "--orbit",
                                         "3",
                                         "--width",
                                         "64",
                                         "--height",
                                         "36",
                                         "-o",
                                         (out / "t_%d.exr").string()};
  ASSERT_EQ(render(args).exit_code, 0);
  const fs::path manifest = out / "manifest.jsonl";
  const std::string complete = read_file(manifest);
  ASSERT_EQ(std::count(complete.begin(), complete.end(), '\n'), 3);
  // Frame 1's file is lost and the manifest ends in half a line, as a kill mid-write leaves it.
  fs::remove(out / "t_1.exr");
  std::ofstream(manifest, std::ios::app) << R"({"frame":1,"frames":3,"number":1,"camera":"orb)";
  const auto resumed = render(args);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_TRUE(contains(resumed.err, "2 already done")) << resumed.err;
  EXPECT_TRUE(contains(resumed.err, "1 frames rendered")) << resumed.err;
  const std::string repaired = read_file(manifest);
  EXPECT_EQ(repaired.substr(0, complete.size()), complete) << "the complete lines must stay as they were";
  EXPECT_EQ(repaired.back(), '\n');
  EXPECT_EQ(std::count(repaired.begin(), repaired.end(), '\n'), 4);
  EXPECT_EQ(manifest_entries(out).size(), 4u);  // every line parses
  EXPECT_TRUE(fs::exists(out / "t_1.exr"));

  std::ofstream(manifest, std::ios::app) << "{\"frame\": \"one\"}\n";
  const auto malformed = render(args);
  EXPECT_EQ(malformed.exit_code, 1) << malformed.err;
  expect_one_error_line(malformed, "tilesplat-render");
  EXPECT_TRUE(contains(malformed.err, "manifest.jsonl' line 5 is not a manifest entry")) << malformed.err;
}

// The merge refuses shards that do not fit together: a frame claimed by two shards, and shards that
// disagree on how many frames the run has.
TEST(RenderSequence, MergeRefusesAFrameInTwoShardsAndShardsOfDifferentRuns) {
  const fs::path root = fresh_output_dir();
  const std::string scene = tilesplat::testing::bundled_playbot().string();
  auto shard = [&](const fs::path& folder, int frames, int index) {
    fs::create_directories(folder);
    const auto result =
        render({scene, "--orbit", std::to_string(frames), "--width", "48", "--height", "27", "--shard",
                std::to_string(index) + "/2", "-o", (folder / "m_%02d.exr").string()});
    EXPECT_EQ(result.exit_code, 0) << result.err;
  };
  const fs::path twice = root / "twice";
  shard(twice, 4, 0);
  shard(twice, 4, 1);
  ASSERT_EQ(render({"--merge-manifests", twice.string()}).exit_code, 0);
  // Shard 0's manifest also claims frame 1 of shard 1 (its line copied over).
  const std::string shard1 = read_file(twice / "manifest.shard-1-of-2.jsonl");
  std::ofstream(twice / "manifest.shard-0-of-2.jsonl", std::ios::app)
      << shard1.substr(0, shard1.find('\n') + 1);
  const auto both = render({"--merge-manifests", twice.string()});
  EXPECT_EQ(both.exit_code, 1) << both.err;
  expect_one_error_line(both, "tilesplat-render");
  EXPECT_TRUE(contains(both.err,
                       "frame 1 is in both 'manifest.shard-0-of-2.jsonl' and "
                       "'manifest.shard-1-of-2.jsonl': each frame must belong to exactly one shard"))
      << both.err;

  const fs::path mixed = root / "mixed";
  shard(mixed, 4, 0);
  shard(mixed, 6, 1);
  const auto disagree = render({"--merge-manifests", mixed.string()});
  EXPECT_EQ(disagree.exit_code, 1) << disagree.err;
  expect_one_error_line(disagree, "tilesplat-render");
  EXPECT_TRUE(contains(disagree.err,
                       "the manifests disagree on the number of frames: "
                       "'manifest.shard-0-of-2.jsonl' has 4, 'manifest.shard-1-of-2.jsonl' 6"))
      << disagree.err;
  EXPECT_FALSE(fs::exists(mixed / "manifest.jsonl"));
}

}  // namespace
