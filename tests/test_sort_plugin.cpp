// The sort extension point (tilesplat/sort_strategy.h): the example strategy of examples/custom_sort
// run as a plugin of tilesplat-bench (the frame benchmark's image check and the sort benchmark's
// order check), as a program that registers it, and loaded into this process; and the errors of
// registering and loading.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/sort_strategy.h"

namespace {

namespace fs = std::filesystem;
using tilesplat::testing::bundled_playbot;
using tilesplat::testing::fresh_output_dir;
using tilesplat::testing::ProcessResult;
using tilesplat::testing::read_file;
using tilesplat::testing::run_process;

constexpr const char* kPlugin = TILESPLAT_SORT_PLUGIN;
constexpr const char* kName = "serial-radix";

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(SortPlugin, ExampleProgramMatchesTheBuiltInRadixSort) {
  const ProcessResult result =
      run_process("", TILESPLAT_CUSTOM_SORT_EXE, {bundled_playbot().string(), "160", "90"});
  ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
  EXPECT_TRUE(contains(result.out, "100000 random 32-bit keys: same order")) << result.out;
  EXPECT_TRUE(contains(result.out, "100000 random 64-bit keys: same order")) << result.out;
  EXPECT_TRUE(contains(result.out, "at 160x90: bit-identical images")) << result.out;
}

// The frame benchmark renders with each strategy and compares every image with the first exact
// strategy's: a plugin strategy gets the same check, and its rows carry the image difference.
TEST(SortPlugin, BenchTimesThePluginBesideTheBuiltInStrategiesWithIdenticalImages) {
  const fs::path out = fresh_output_dir();
  const fs::path csv = out / "frames.csv";
  const ProcessResult result = run_process(
      "", TILESPLAT_BENCH_EXE,
      {bundled_playbot().string(), "--sort-plugin", kPlugin, "--sort", std::string("radix,") + kName,
       "--width", "96", "--height", "54", "--warmup", "0", "--repeat", "1", "--csv", csv.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_FALSE(contains(result.err, "different images")) << result.err;
  EXPECT_TRUE(contains(result.out, kName)) << result.out;
  std::ifstream lines(csv);
  std::string line;
  int checked = 0;
  while (std::getline(lines, line)) {
    if (!contains(line, std::string(",") + kName + ",frame,image max abs vs exact,")) continue;
    EXPECT_TRUE(contains(line, ",image max abs vs exact,,frames,0,0,0,1,")) << line;
    ++checked;
  }
  EXPECT_EQ(checked, 1) << read_file(csv);
}

// The sort benchmark fails the run when an exact strategy's order differs from the CPU radix sort's.
TEST(SortPlugin, SortBenchHoldsThePluginToTheExactOrder) {
  const ProcessResult result =
      run_process("", TILESPLAT_BENCH_EXE,
                  {"--sort-bench", "--sort-plugin", kPlugin, "--sort", kName, "--sort-sizes", "10,15",
                   "--key-bits", "32,64", "--warmup", "0", "--repeat", "1"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.out, kName)) << result.out;
}

TEST(SortPlugin, HelpListsThePluginsStrategies) {
  const ProcessResult with = run_process("", TILESPLAT_RENDER_EXE, {"--sort-plugin", kPlugin, "--help"});
  ASSERT_EQ(with.exit_code, 0) << with.err;
  EXPECT_TRUE(contains(with.out, std::string(", ") + kName + " (default auto")) << with.out;
  const ProcessResult without = run_process("", TILESPLAT_RENDER_EXE, {"--help"});
  EXPECT_FALSE(contains(without.out, kName)) << without.out;
}

TEST(SortPlugin, LoadsIntoTheProcessAndSortsLikeRadix) {
  EXPECT_EQ(tilesplat::load_sort_plugin(kPlugin), std::vector<std::string>{kName});
  EXPECT_EQ(tilesplat::load_sort_plugin(kPlugin), std::vector<std::string>{kName});  // once only
  const auto names = tilesplat::sort_strategies();
  EXPECT_EQ(names.front(), "radix");
  EXPECT_EQ(names.back(), kName);
  EXPECT_TRUE(tilesplat::sort_strategy_is_exact(kName));

  auto& renderer = tilesplat::testing::validated_renderer();
  std::mt19937_64 random(7);
  std::vector<uint64_t> keys(5000);
  for (auto& key : keys) key = random() & 0x3F00FF00FFull;  // 38 bits, many ties
  const auto expected = renderer.sort_keys("radix", keys, 38);
  const auto sorted = renderer.sort_keys(kName, keys, 38);
  EXPECT_EQ(sorted.order, expected.order);
  EXPECT_EQ(sorted.keys, expected.keys);
  const auto empty = renderer.sort_keys(kName, {}, 32);
  EXPECT_TRUE(empty.order.empty());

  const tilesplat::GaussianScene scene = tilesplat::load_scene(bundled_playbot());
  renderer.set_scene(scene);
  const tilesplat::Camera camera = tilesplat::orbit_camera(scene, 128, 72);
  tilesplat::RenderSettings settings;
  settings.reuse_lists = false;
  const tilesplat::RenderImage radix = renderer.render(camera, settings);
  settings.sort = kName;
  const tilesplat::RenderImage plugin = renderer.render(camera, settings);
  EXPECT_GT(renderer.last_frame_stats().device_bytes, 0u);
  EXPECT_EQ(plugin.rgba, radix.rgba);
  EXPECT_EQ(plugin.depth, radix.depth);
  EXPECT_EQ(plugin.splat_count, radix.splat_count);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(SortPlugin, LoadingErrorsNameTheFile) {
  const fs::path dir = fresh_output_dir();
  const fs::path missing = dir / "missing.so";
  EXPECT_EQ(tilesplat::testing::error_of([&] { tilesplat::load_sort_plugin(missing); }),
            "cannot load sort plugin " + missing.string() + ": the file does not exist");
  EXPECT_EQ(tilesplat::testing::error_of([&] { tilesplat::load_sort_plugin(dir); }),
            "cannot load sort plugin " + dir.string() + ": it is not a regular file");
  const fs::path text = dir / "text.so";
  std::ofstream(text) << "not a shared object\n";
  const std::string not_elf = tilesplat::testing::error_of([&] { tilesplat::load_sort_plugin(text); });
  EXPECT_EQ(not_elf.rfind("cannot load sort plugin " + text.string() + ": ", 0), 0u) << not_elf;
  EXPECT_EQ(
      tilesplat::testing::error_of([&] { tilesplat::load_sort_plugin(TILESPLAT_PLUGIN_WITHOUT_ENTRY); }),
      std::string("cannot load sort plugin ") + TILESPLAT_PLUGIN_WITHOUT_ENTRY +
          ": it exports no function tilesplat_sort_plugin_v1 (declare it extern \"C\" and visible)");
  EXPECT_EQ(tilesplat::testing::error_of(
                [&] { tilesplat::load_sort_plugin(TILESPLAT_PLUGIN_REGISTERING_NOTHING); }),
            std::string("cannot load sort plugin ") + TILESPLAT_PLUGIN_REGISTERING_NOTHING +
                ": it registered no sort strategy");
  EXPECT_THROW(tilesplat::load_sort_plugin(missing), std::runtime_error);

  // The apps: one error line, exit 1, nothing written.
  const ProcessResult result =
      run_process("", TILESPLAT_BENCH_EXE,
                  {"--sort-plugin", missing.string(), "--sort-bench", "--csv", (dir / "out.csv").string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  tilesplat::testing::expect_one_error_line(result, "tilesplat-bench");
  EXPECT_TRUE(contains(result.err, missing.string() + ": the file does not exist")) << result.err;
  EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

TEST(SortPlugin, RegistrationRejectsBadNames) {
  const auto factory = [](const tilesplat::SortDevice&) -> std::unique_ptr<tilesplat::ExternalSortStrategy> {
    throw std::runtime_error("never made");
  };
  EXPECT_EQ(tilesplat::testing::error_of([&] { tilesplat::register_sort_strategy("", factory); }),
            "a sort strategy needs a name");
  EXPECT_EQ(tilesplat::testing::error_of([&] { tilesplat::register_sort_strategy("a,b", factory); }),
            "sort strategy name 'a,b' contains a comma or whitespace (names are listed comma-separated)");
  EXPECT_EQ(tilesplat::testing::error_of([&] { tilesplat::register_sort_strategy("radix", factory); }),
            "a sort strategy named 'radix' is already registered");
  EXPECT_EQ(tilesplat::testing::error_of([&] { tilesplat::register_sort_strategy("no-factory", nullptr); }),
            "sort strategy 'no-factory' has no factory");
  EXPECT_THROW(tilesplat::register_sort_strategy("radix", factory), std::invalid_argument);

  // A factory that throws fails the frame that needs it, with its message, and nothing else. Scoped, so
  // that no later test in the same process finds it among the strategies.
  {
    const tilesplat::ScopedSortStrategy throws("throws-on-creation", factory);
    EXPECT_EQ(tilesplat::sort_strategies().back(), "throws-on-creation");
    EXPECT_EQ(tilesplat::testing::error_of(
                  [&] { tilesplat::ScopedSortStrategy again("throws-on-creation", factory); }),
              "a sort strategy named 'throws-on-creation' is already registered");
    auto& renderer = tilesplat::testing::validated_renderer();
    EXPECT_EQ(tilesplat::testing::error_of([&] {
                renderer.sort_keys("throws-on-creation", {3, 1, 2}, 8);
              }),
              "never made");
    EXPECT_EQ(renderer.sort_keys("radix", {3, 1, 2}, 8).order, (std::vector<uint32_t>{1, 2, 0}));
  }
  // Gone with its handle; the built-in ones stay, and the name may be registered again.
  const std::vector<std::string> after = tilesplat::sort_strategies();
  EXPECT_EQ(std::find(after.begin(), after.end(), "throws-on-creation"), after.end());
  EXPECT_NE(std::find(after.begin(), after.end(), "radix"), after.end());
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::testing::validated_renderer().sort_keys("throws-on-creation", {3, 1, 2}, 8);
            }).find("unknown sort strategy 'throws-on-creation'"),
            std::string::npos);
  tilesplat::ScopedSortStrategy moved_from("throws-on-creation", factory);
  const tilesplat::ScopedSortStrategy owner = std::move(moved_from);
  EXPECT_EQ(owner.name(), "throws-on-creation");
  EXPECT_EQ(moved_from.name(), "");  // NOLINT(bugprone-use-after-move): a moved-from handle owns nothing
}

}  // namespace
