// The host sort strategies (cpu-radix, cpu-radix16) on both of their paths: sorting in the mapped
// device memory and copying through staging. cpu-radix against std::stable_sort; cpu-radix16
// against a model of its quantization (the formula in sort/cpu_radix_strategy.h) sorted by
// std::stable_sort; and both in a frame through the public API.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

#include "passes/frame_counters.h"
#include "sort/cpu_radix_strategy.h"
#include "sort_test_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/context.h"
#include "vulkan/gpu_timer.h"

namespace tilesplat {
namespace {

using Keys = CpuRadixSort::Keys;
using HostAccess = CpuRadixSort::HostAccess;

using namespace testing;

struct HostSortResult {
  SortedPairs pairs;
  bool used_staging = false;
  double host_ms = 0;   // the strategy's own sort time
  double timed_ms = 0;  // GPU timestamps around record(), across its submissions
  int submissions = 0;
};

HostSortResult host_sort(Keys which, HostAccess access, const std::vector<uint64_t>& keys, uint32_t key_bits,
                         bool depth_in_low_bits) {
  vk::Context& ctx = sort_test_context();
  // The count is set on the GPU, as in a frame: the strategy must flush before it reads it.
  DeviceSortInput in = upload_sort_input(keys, key_bits, 0, /*count_on_host=*/false);

  CpuRadixSort sorter(ctx, which, access);
  sorter.reserve(in.buffers.capacity);
  vk::GpuTimer timer(ctx);
  vk::CommandStream stream(ctx);
  timer.begin_frame(stream.cmd());
  vkCmdFillBuffer(stream.cmd(), in.counters.handle(), kTileSortOffset + offsetof(SortState, count), 4, in.count);
  vk::barrier(stream.cmd());
  SortInput input = in.input(key_bits, depth_in_low_bits);
  const bool in_alt = sorter.record(stream, input);
  timer.mark(stream.cmd(), "sort");
  stream.finish();

  HostSortResult result;
  timer.read(&result.timed_ms);
  result.used_staging = sorter.last_used_staging();
  result.host_ms = sorter.last_host_ms();
  result.submissions = stream.submissions();
  result.pairs = read_sorted(in.buffers, in_alt, in.count);
  return result;
}

void expect_host_order(const HostSortResult& got, const std::vector<uint64_t>& keys,
                       const std::vector<uint32_t>& expected, const std::string& what) {
  expect_order(keys, expected, got.pairs, what);
}

// The quantization as sort/cpu_radix_strategy.h states it, written out independently.
std::vector<uint64_t> quantized_keys(const std::vector<uint64_t>& keys, uint32_t key_bits, bool depth_in_low_bits) {
  if (key_bits <= 16) return keys;
  std::vector<uint64_t> q(keys.size());
  if (depth_in_low_bits) {
    auto depth_of = [](uint64_t key) { return std::bit_cast<float>(uint32_t(key & 0xffffffffu)); };
    auto valid = [&](uint64_t key) { return std::isfinite(depth_of(key)) && depth_of(key) > 0; };
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (uint64_t k : keys)
      if (valid(k)) lo = std::min(lo, depth_of(k)), hi = std::max(hi, depth_of(k));
    for (size_t i = 0; i < keys.size(); ++i) {
      uint64_t level = 65535;
      if (valid(keys[i]))
        level = hi > lo ? std::min<uint64_t>(65534, uint64_t((double(depth_of(keys[i])) - double(lo)) *
                                                             (65534.0 / (double(hi) - double(lo)))))
                        : 0;
      q[i] = ((keys[i] >> 32) << 16) | level;
    }
  } else {
    const auto [lo, hi] = std::minmax_element(keys.begin(), keys.end());
    for (size_t i = 0; i < keys.size(); ++i)
      q[i] = *hi > *lo ? std::min<uint64_t>(65535, uint64_t(double(keys[i] - *lo) * (65535.0 / double(*hi - *lo))))
                       : 0;
  }
  return q;
}

// View depths as the projection writes them: float bits of depths in [0.2, 60], from `distinct`
// values (0: any), with a share of culled Gaussians (0xffffffff) and, optionally, other keys that
// are no finite positive float (0, -1, +inf, a NaN). `tile_bits` > 0 puts random tile ids above.
std::vector<uint64_t> depth_keys(size_t n, uint64_t seed, uint32_t distinct, double culled_share, bool odd_values,
                                 uint32_t tile_bits = 0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> depth(0.2f, 60.0f);
  std::vector<float> palette(distinct);
  for (auto& d : palette) d = depth(rng);
  std::vector<uint64_t> keys(n);
  const uint32_t odd[] = {0u, std::bit_cast<uint32_t>(-1.0f), 0x7f800000u, 0x7fc00001u};
  for (auto& k : keys) {
    const double u = std::uniform_real_distribution<double>(0, 1)(rng);
    uint32_t bits;
    if (u < culled_share)
      bits = 0xffffffffu;
    else if (odd_values && u < culled_share + 0.01)
      bits = odd[rng() % 4];
    else
      bits = std::bit_cast<uint32_t>(distinct ? palette[rng() % distinct] : depth(rng));
    k = bits;
    if (tile_bits) k |= (rng() & ((1ull << tile_bits) - 1)) << 32;
  }
  return keys;
}

constexpr HostAccess kBothPaths[] = {HostAccess::kAuto, HostAccess::kStaging};

const char* path_name(HostAccess access) { return access == HostAccess::kAuto ? "auto" : "staging"; }

TEST(CpuRadixStrategy, ExactOnBothPathsMatchesStableSort) {
  for (const HostAccess access : kBothPaths) {
    for (const size_t n : {size_t(0), size_t(1), size_t(257), size_t(100000)}) {
      for (const uint32_t bits : {9u, 32u, 45u, 64u}) {
        const auto keys = random_keys(n, bits, n * 64 + bits, n > 1000 ? 300 : 0);
        const std::string what = std::string("cpu-radix ") + path_name(access) + " " + std::to_string(bits) + " bits";
        const HostSortResult got = host_sort(Keys::kExact, access, keys, bits, false);
        expect_host_order(got, keys, stable_order(keys), what);
        EXPECT_EQ(got.used_staging, access == HostAccess::kStaging || !sort_test_context().is_cpu_device()) << what;
      }
    }
  }
  // Depth keys in the depth sort's form: exact means exact, culled keys included.
  const auto keys = depth_keys(50000, 5, 0, 0.1, true);
  expect_host_order(host_sort(Keys::kExact, HostAccess::kAuto, keys, 32, true), keys, stable_order(keys),
               "cpu-radix depth keys");
  EXPECT_EQ(sort_test_context().validation_messages(), 0u);
}

TEST(CpuRadixStrategy, Quantized16MatchesTheModelOnDepthKeys) {
  struct Case {
    std::string name;
    std::vector<uint64_t> keys;
    uint32_t bits;
  };
  const std::vector<Case> cases = {
      {"distinct depths", depth_keys(100000, 1, 0, 0.05, false), 32},
      {"many equal depths", depth_keys(100000, 2, 40, 0.2, false), 32},
      {"odd keys", depth_keys(30000, 3, 0, 0.1, true), 32},
      {"one key", {std::bit_cast<uint32_t>(3.5f)}, 32},
      {"all depths equal", std::vector<uint64_t>(5000, std::bit_cast<uint32_t>(7.25f)), 32},
      {"equal depths and culled", depth_keys(5000, 4, 1, 0.5, false), 32},
      {"all culled", std::vector<uint64_t>(3000, 0xffffffffu), 32},
      {"tile and depth", depth_keys(100000, 5, 0, 0.05, true, 13), 45},
      {"wide tile and depth", depth_keys(20000, 6, 500, 0.05, true, 24), 56},
  };
  for (const Case& c : cases) {
    const std::vector<uint32_t> expected = stable_order(quantized_keys(c.keys, c.bits, true));
    for (const HostAccess access : kBothPaths) {
      const std::string what = "cpu-radix16 " + std::string(path_name(access)) + ", " + c.name;
      expect_host_order(host_sort(Keys::kQuantized16, access, c.keys, c.bits, true), c.keys, expected, what);
    }
  }
  // The model must tell a quantized order from the exact one, or the checks above prove nothing.
  EXPECT_NE(stable_order(quantized_keys(cases[0].keys, 32, true)), stable_order(cases[0].keys));
  EXPECT_EQ(sort_test_context().validation_messages(), 0u);
}

TEST(CpuRadixStrategy, Quantized16MatchesTheModelOnIntegerKeys) {
  for (const HostAccess access : kBothPaths) {
    for (const uint32_t bits : {17u, 32u, 45u, 64u}) {
      for (const uint64_t distinct : {uint64_t(0), uint64_t(50)}) {
        const auto keys = random_keys(70000, bits, bits + distinct, distinct);
        const std::string what = "cpu-radix16 " + std::string(path_name(access)) + " " + std::to_string(bits) +
                                 " bits, " + std::to_string(distinct) + " distinct";
        expect_host_order(host_sort(Keys::kQuantized16, access, keys, bits, false), keys,
                     stable_order(quantized_keys(keys, bits, false)), what);
      }
    }
    const std::vector<uint64_t> equal(1000, 123456789);
    expect_host_order(host_sort(Keys::kQuantized16, access, equal, 32, false), equal, stable_order(equal),
                 "cpu-radix16 all keys equal");
    // Up to 16 key bits nothing is quantized.
    const auto narrow = random_keys(50000, 16, 77, 0);
    expect_host_order(host_sort(Keys::kQuantized16, access, narrow, 16, false), narrow, stable_order(narrow),
                 "cpu-radix16 16-bit keys");
  }
  const auto keys = random_keys(50000, 32, 9);
  EXPECT_NE(stable_order(quantized_keys(keys, 32, false)), stable_order(keys));
  EXPECT_EQ(sort_test_context().validation_messages(), 0u);
}

// The sort's timer marks lie in different submissions, with the host sort between them: the time
// they report must include it, and the copies when there are any.
TEST(CpuRadixStrategy, TimerMarksSpanTheHostSort) {
  const auto keys = random_keys(1u << 20, 32, 21);
  for (const HostAccess access : kBothPaths) {
    const HostSortResult got = host_sort(Keys::kExact, access, keys, 32, false);
    EXPECT_GT(got.host_ms, 0.0);
    EXPECT_GE(got.timed_ms, got.host_ms) << path_name(access);
    EXPECT_EQ(got.submissions, got.used_staging ? 3 : 2) << path_name(access);
  }
}

TEST(CpuRadixStrategy, RegisteredAndExactnessAgrees) {
  const auto names = sort_strategies();
  for (const char* name : {"cpu-radix", "cpu-radix16"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  for (const auto& name : names)
    EXPECT_EQ(sort_strategy_is_exact(name), make_sort_strategy(name, sort_test_context())->exact()) << name;
  EXPECT_FALSE(sort_strategy_is_exact("cpu-radix16"));
  EXPECT_TRUE(sort_strategy_is_exact("cpu-radix"));
  EXPECT_THROW(sort_strategy_is_exact("no-such-sort"), std::invalid_argument);
}

// A frame through the public API: "auto" picks per device type; the host sorts split a frame into
// several submissions, their pass times include the host sort, cpu-radix's image is radix's to the
// bit and cpu-radix16's is close to it (40 dB PSNR; the 16-bit depths swap Gaussians only within
// 1/65535 of the depth range).
TEST(CpuRadixStrategy, FramesMatchRadix) {
  constexpr double kMinPsnrDb = 40;
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(load_ply(testing::bundled_playbot()));
  const Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(1).camera, 480, 270);
  // The default sort, "auto", is cpu-radix on a CPU driver, onesweep on NVIDIA and radix on other GPUs,
  // with radix's image.
  RenderSettings settings;
  const RenderImage automatic = renderer.render(camera, settings);
  const bool cpu = renderer.device_info().cpu;
  EXPECT_EQ(renderer.last_frame_stats().sort_strategy, cpu ? "cpu-radix"
                                                       : renderer.device_info().vendor_id == 0x10DE
                                                           ? "onesweep"
                                                           : "radix");
  EXPECT_EQ(renderer.last_frame_stats().submissions > 1, cpu);
  settings.sort = "radix";
  const RenderImage exact = renderer.render(camera, settings);
  ASSERT_EQ(renderer.last_frame_stats().submissions, 1);
  EXPECT_EQ(renderer.last_frame_stats().sort_strategy, "radix");
  EXPECT_EQ(automatic.rgba, exact.rgba);
  EXPECT_EQ(automatic.depth, exact.depth);
  const uint64_t intersections = renderer.last_frame_stats().intersections;
  ASSERT_GT(intersections, 10000u);
  for (const char* strategy : {"cpu-radix", "cpu-radix16"}) {
    settings.sort = strategy;
    const RenderImage image = renderer.render(camera, settings);
    const FrameStats& stats = renderer.last_frame_stats();
    EXPECT_GT(stats.submissions, 1) << strategy;
    EXPECT_EQ(stats.intersections, intersections) << strategy;
    double sort_ms = 0;
    for (const auto& pass : stats.passes)
      if (pass.name == "depth_sort" || pass.name == "tile_sort") {
        EXPECT_GT(pass.gpu_ms, 0.0) << strategy << " " << pass.name;
        sort_ms += pass.gpu_ms;
      }
    EXPECT_GT(sort_ms, 0.0) << strategy;
    EXPECT_LE(stats.gpu_ms, stats.cpu_ms) << strategy;
    const ImageDifference diff = compare_images(image, exact);
    std::printf("%s: %d submissions, sorts %.2f ms of %.2f ms, %.2f dB PSNR against radix (max |d| %.4f)\n",
                strategy, stats.submissions, sort_ms, stats.gpu_ms, diff.psnr_db, diff.max_abs);
    if (sort_strategy_is_exact(strategy)) {
      EXPECT_EQ(image.rgba, exact.rgba) << strategy;
      EXPECT_EQ(image.depth, exact.depth) << strategy;
      EXPECT_EQ(image.splat_count, exact.splat_count) << strategy;
    } else {
      EXPECT_GE(diff.psnr_db, kMinPsnrDb) << strategy;
      EXPECT_NE(image.rgba, exact.rgba) << strategy << ": quantized depths changed nothing; is it quantizing?";
    }
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

}  // namespace
}  // namespace tilesplat
