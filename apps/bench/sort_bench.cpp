#include "sort_bench.h"

#include <chrono>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>

#include "bench_plot.h"
#include "bench_results.h"
#include "frame_bench.h"
#include "progress.h"
#include "tilesplat/sort.h"

namespace tilesplat::bench {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;
namespace plot = tilesplat::plot;

namespace {

struct SortRow {
  int key_bits = 0;
  uint64_t keys = 0;
  std::string sorter;
  std::string where;  // "gpu" (GPU timestamps of the sort alone) or "cpu" (wall clock, one thread)
  std::vector<double> ms;
  // A quantizing strategy's cost in accuracy: the fraction of output positions whose key is not the
  // one an exact sort puts there (0 for the exact ones, which are checked to give the exact order).
  double misordered = 0;
  // Sorts' look-back steps that stopped waiting and took the fallback path (onesweep), summed over
  // the timed runs: the forward-progress cost the strategy paid on this device.
  uint64_t fallbacks = 0;
};

// Checks that an inexact strategy's order is a permutation, and returns the fraction of positions
// whose key differs from the exact order's key at that position.
double misordered_fraction(const std::vector<uint64_t>& keys, const std::vector<uint32_t>& exact,
                           const std::vector<uint32_t>& order, const std::string& sort,
                           const std::string& label) {
  std::vector<bool> seen(keys.size(), false);
  bool permutation = order.size() == keys.size();
  for (size_t i = 0; permutation && i < order.size(); ++i) {
    permutation = order[i] < keys.size() && !seen[order[i]];
    if (permutation) seen[order[i]] = true;
  }
  if (!permutation)
    throw std::runtime_error("sort strategy '" + sort + "' did not return a permutation of the keys on " +
                             label);
  size_t differing = 0;
  for (size_t i = 0; i < order.size(); ++i) differing += keys[order[i]] != keys[exact[i]];
  return order.empty() ? 0.0 : double(differing) / double(order.size());
}

std::vector<uint64_t> random_keys(uint64_t n, int bits, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const uint64_t mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
  std::vector<uint64_t> keys(n);
  for (auto& key : keys) key = rng() & mask;
  return keys;
}

template <typename F>
double wall_ms(F&& body) {
  const auto start = std::chrono::steady_clock::now();
  body();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// std::sort on (key, position) pairs: the same job as the strategies' (ascending keys, equal keys in
// input order), done the way a C++ programmer would without a radix sort.
double time_std_sort(const std::vector<uint64_t>& keys) {
  std::vector<std::pair<uint64_t, uint32_t>> pairs(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) pairs[i] = {keys[i], uint32_t(i)};
  return wall_ms([&] { std::sort(pairs.begin(), pairs.end()); });
}

double time_cpu_radix(const std::vector<uint64_t>& keys, int bits, std::vector<uint32_t>* order) {
  std::vector<uint64_t> sorted = keys;
  std::vector<uint32_t> values(keys.size());
  std::iota(values.begin(), values.end(), 0u);
  const double ms = wall_ms([&] { tilesplat::cpu_radix_sort(sorted, values, uint32_t(bits)); });
  if (order) *order = std::move(values);
  return ms;
}

double median_ms(const SortRow& row) {
  return summarize(row.ms).median;
}

double mkeys_per_s(const SortRow& row) {
  const double ms = median_ms(row);
  return ms > 0 ? double(row.keys) / ms / 1e3 : 0;
}

// How many times faster than std::sort on the same keys (0 when unknown).
double vs_std_sort(const std::vector<SortRow>& rows, const SortRow& row) {
  const double ms = median_ms(row);
  for (const auto& other : rows)
    if (other.key_bits == row.key_bits && other.keys == row.keys && other.sorter == "std::sort")
      return ms > 0 ? median_ms(other) / ms : 0;
  return 0;
}

std::string make_sort_csv(const std::vector<SortRow>& rows, const tilesplat::DeviceInfo& device) {
  std::string csv =
      "device,key_bits,keys,sorter,where,median_ms,min_ms,max_ms,mkeys_per_s,vs_std_sort,misordered,"
      "fallbacks,samples\n";
  for (const auto& row : rows) {
    const Summary s = summarize(row.ms);
    csv += cli::csv_field(device.name) + "," + std::to_string(row.key_bits) + "," + std::to_string(row.keys) +
           "," + cli::csv_field(row.sorter) + "," + row.where + "," + number_text(s.median) + "," +
           number_text(s.min) + "," + number_text(s.max) + "," + number_text(mkeys_per_s(row)) + "," +
           number_text(vs_std_sort(rows, row)) + "," + number_text(row.misordered) + "," +
           std::to_string(row.fallbacks) + "," + std::to_string(row.ms.size()) + "\n";
  }
  return csv;
}

std::string make_sort_json(const std::vector<SortRow>& rows, const tilesplat::DeviceInfo& device,
                           const BenchOptions& options) {
  Json json;
  add_provenance(json, "tilesplat-bench --sort-bench", options.command);
  json["device"] = {
      {"name", device.name}, {"driver", device.driver}, {"subgroup_size", device.subgroup_size}};
  json["warmup"] = options.warmup;
  json["repeat"] = options.repeat;
  Json& results = json["results"] = Json::array();
  for (const auto& row : rows) {
    const Summary s = summarize(row.ms);
    Json samples = Json::array();
    for (const double ms : row.ms) samples.push_back(json_number(ms));
    results.push_back({{"key_bits", row.key_bits},
                       {"keys", row.keys},
                       {"sorter", row.sorter},
                       {"where", row.where},
                       {"median_ms", json_number(s.median)},
                       {"min_ms", json_number(s.min)},
                       {"max_ms", json_number(s.max)},
                       {"misordered", json_number(row.misordered)},
                       {"fallbacks", row.fallbacks},
                       {"samples_ms", std::move(samples)}});
  }
  return json.dump(2) + "\n";
}

// A line per sorter and key width: the colour tells the sorter, the dash the key width.
std::string make_sort_svg(const std::vector<SortRow>& rows, const tilesplat::DeviceInfo& device,
                          const BenchOptions& options) {
  plot::LineChart chart;
  chart.title = "Sort throughput against key count";
  chart.subtitle = device_line(device) + "; median of " + std::to_string(options.repeat) +
                   " sorts; GPU: the sort alone (timestamps), CPU: one thread";
  chart.x_label = "keys";
  chart.y_label = "Mkeys/s";
  chart.x_scale = plot::Scale::kLog2;
  std::vector<std::string> sorters;
  std::vector<int> widths;
  double min = std::numeric_limits<double>::infinity();
  double max = 0;
  for (const auto& row : rows) {
    add_unique(sorters, row.sorter);
    add_unique(widths, row.key_bits);
    const std::string label =
        row.sorter + (row.where == "cpu" ? " (cpu)" : "") + ", " + std::to_string(row.key_bits) + "-bit keys";
    auto series = std::find_if(chart.series.begin(), chart.series.end(),
                               [&](const plot::LineSeries& line) { return line.label == label; });
    if (series == chart.series.end()) {
      const auto index = [](const auto& items, const auto& item) {
        return size_t(std::find(items.begin(), items.end(), item) - items.begin());
      };
      chart.series.push_back({label, index(sorters, row.sorter), index(widths, row.key_bits), {}});
      series = chart.series.end() - 1;
    }
    const double rate = mkeys_per_s(row);
    series->points.emplace_back(double(row.keys), rate);
    if (rate > 0) {
      min = std::min(min, rate);
      max = std::max(max, rate);
    }
  }
  // Small GPU sorts run at a hundredth of the CPU sorts' rate: a linear axis would flatten them to 0.
  chart.y_scale = max >= 20 * min ? plot::Scale::kLog10 : plot::Scale::kLinear;
  return plot::line_chart_svg(chart);
}

}  // namespace

int run_sort_bench(const BenchOptions& options) {
  check_outputs(options, {});

  std::vector<std::string> sorts = options.common.sorts;
  if (sorts.empty()) sorts = tilesplat::sort_strategies();
  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  const tilesplat::DeviceInfo device = renderer->device_info();
  std::printf("device  %s (driver %s), subgroup size %u\n", device.name.c_str(), device.driver.c_str(),
              device.subgroup_size);
  print_auto_choice(*renderer, sorts);
  std::printf(
      "sorts   %d warm-up + %d measured per row; GPU rows time the sort alone (timestamps), CPU rows\n"
      "        are one thread of this machine's CPU; every GPU result is checked against the CPU radix "
      "sort\n",
      options.warmup, options.repeat);
  std::fflush(stdout);

  const int runs_per_row = options.warmup + options.repeat;
  const int rows_per_case = int(sorts.size()) + 2;
  const int total = runs_per_row * rows_per_case * int(options.key_bits.size() * options.sort_sizes.size());
  std::vector<SortRow> rows;
  const auto start = std::chrono::steady_clock::now();
  {
    cli::FrameProgress progress(kProgram, total, cli::progress_style(false), "sorts");
    int done = 0;
    for (const int bits : options.key_bits) {
      for (const int exponent : options.sort_sizes) {
        const uint64_t n = 1ull << exponent;
        const auto keys = random_keys(n, bits, n * 131 + uint64_t(bits));
        const std::string label = std::to_string(bits) + "-bit, 2^" + std::to_string(exponent) + " keys";
        std::vector<uint32_t> expected;
        SortRow cpu_radix{bits, n, "cpu radix", "cpu", {}};
        for (int run = 0; run < runs_per_row; ++run) {
          const double ms = time_cpu_radix(keys, bits, run == 0 ? &expected : nullptr);
          if (run >= options.warmup) cpu_radix.ms.push_back(ms);
          progress.update(++done, label + ", cpu radix");
        }
        SortRow std_sort{bits, n, "std::sort", "cpu", {}};
        for (int run = 0; run < runs_per_row; ++run) {
          const double ms = time_std_sort(keys);
          if (run >= options.warmup) std_sort.ms.push_back(ms);
          progress.update(++done, label + ", std::sort");
        }
        for (const auto& sort : sorts) {
          SortRow row{bits, n, sort, "gpu", {}};
          const bool exact = tilesplat::sort_strategy_is_exact(sort);
          for (int run = 0; run < runs_per_row; ++run) {
            const auto result = renderer->sort_keys(sort, keys, uint32_t(bits));
            if (run == 0 && exact && result.order != expected) {
              progress.finish();
              throw std::runtime_error("sort strategy '" + sort +
                                       "' gave a different order than the CPU radix "
                                       "sort on " +
                                       label);
            }
            if (run == 0 && !exact)
              row.misordered = misordered_fraction(keys, expected, result.order, sort, label);
            if (run >= options.warmup) {
              row.ms.push_back(result.gpu_ms);
              row.fallbacks += result.fallbacks;
            }
            progress.update(++done, label + ", " + sort);
          }
          rows.push_back(std::move(row));
        }
        rows.push_back(std::move(std_sort));
        rows.push_back(std::move(cpu_radix));
      }
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::printf("\n  %4s %10s  %-12s %-4s %12s %12s %12s %11s %10s\n", "bits", "keys", "sorter", "on",
              "median ms", "Mkeys/s", "vs std::sort", "misordered", "fallbacks");
  for (const auto& row : rows)
    std::printf("  %4d %10llu  %-12s %-4s %12s %12s %11sx %10s%% %10llu\n", row.key_bits,
                static_cast<unsigned long long>(row.keys), row.sorter.c_str(), row.where.c_str(),
                cli::format_fixed(median_ms(row), 3).c_str(), cli::format_fixed(mkeys_per_s(row), 2).c_str(),
                cli::format_fixed(vs_std_sort(rows, row), 2).c_str(),
                cli::format_fixed(100.0 * row.misordered, 2).c_str(),
                static_cast<unsigned long long>(row.fallbacks));
  std::fflush(stdout);

  const std::string written = write_outputs(
      {{options.csv,
        [&] { return cli::with_provenance_columns(make_sort_csv(rows, device), options.command); }},
       {options.json, [&] { return make_sort_json(rows, device, options); }},
       {options.plot, [&] { return make_sort_svg(rows, device, options); }}},
      renderer->validation_messages());
  std::fprintf(stderr, "%s: sort micro-benchmark, %d sorts in %s s%s\n", kProgram, total,
               cli::format_fixed(seconds, 2).c_str(), written.c_str());
  return cli::kExitOk;
}

}  // namespace tilesplat::bench
