// tilesplat-bench: times the renderer's passes over repeated frames, per sort strategy; or, with
// --sort-bench, the sort strategies alone on random keys against CPU sorts on the same keys.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "cli.h"
#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/sort.h"

namespace {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;

constexpr const char* kProgram = "tilesplat-bench";

struct BenchOptions {
  cli::CommonOptions common;
  int warmup = 2;
  int repeat = 10;
  std::string csv;
  std::string json;
  bool sort_bench = false;
  std::vector<int> sort_sizes{10, 12, 14, 16, 18, 20, 22, 24};  // log2 of the key counts
  std::vector<int> key_bits{32, 64};
};

enum class Unit { kMilliseconds, kCount, kMebibytes };

const char* unit_name(Unit unit) {
  switch (unit) {
    case Unit::kMilliseconds: return "ms";
    case Unit::kCount: return "";
    case Unit::kMebibytes: return "MiB";
  }
  return "";
}

int unit_decimals(Unit unit) {
  switch (unit) {
    case Unit::kMilliseconds: return 3;
    case Unit::kCount: return 0;
    case Unit::kMebibytes: return 2;
  }
  return 3;
}

// One row of the table: a metric sampled once per measured frame.
struct Series {
  std::string name;
  std::string kind;  // "pass" (GPU time of one pass) or "frame"
  Unit unit = Unit::kMilliseconds;
  std::vector<double> samples;
};

struct Summary {
  double median = 0;
  double min = 0;
  double max = 0;
};

Summary summarize(std::vector<double> samples) {
  Summary summary;
  if (samples.empty()) return summary;
  std::sort(samples.begin(), samples.end());
  const size_t n = samples.size();
  summary.median = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  summary.min = samples.front();
  summary.max = samples.back();
  return summary;
}

struct StrategyResult {
  std::string sort;
  std::vector<Series> passes;  // in frame order (of first appearance)
  std::vector<Series> frame;   // gpu frame, cpu frame, counts, memory
};

// Gathers FrameStats of the measured frames into per-metric series.
class Collector {
 public:
  explicit Collector(std::string sort) { result_.sort = std::move(sort); }

  void add(const tilesplat::FrameStats& stats) {
    // A pass that runs several times a frame (one per radix digit, say) gets one row per run.
    std::vector<std::pair<std::string, int>> occurrences;
    for (const auto& pass : stats.passes) {
      int occurrence = 1;
      for (auto& [name, count] : occurrences)
        if (name == pass.name) occurrence = ++count;
      if (occurrence == 1) occurrences.emplace_back(pass.name, 1);
      const std::string label = occurrence == 1 ? pass.name : pass.name + " #" + std::to_string(occurrence);
      series(result_.passes, label, "pass", Unit::kMilliseconds).samples.push_back(pass.gpu_ms);
    }
    series(result_.frame, "gpu frame", "frame", Unit::kMilliseconds).samples.push_back(stats.gpu_ms);
    series(result_.frame, "cpu frame", "frame", Unit::kMilliseconds).samples.push_back(stats.cpu_ms);
    series(result_.frame, "visible gaussians", "frame", Unit::kCount).samples.push_back(double(stats.visible));
    series(result_.frame, "intersections", "frame", Unit::kCount).samples.push_back(double(stats.intersections));
    series(result_.frame, "sort bits", "frame", Unit::kCount).samples.push_back(double(stats.sort_bits));
    series(result_.frame, "retries", "frame", Unit::kCount).samples.push_back(double(stats.retries));
    series(result_.frame, "device memory", "frame", Unit::kMebibytes)
        .samples.push_back(double(stats.device_bytes) / (1024.0 * 1024.0));
  }

  StrategyResult take() { return std::move(result_); }

 private:
  static Series& series(std::vector<Series>& rows, const std::string& name, const char* kind, Unit unit) {
    for (auto& row : rows)
      if (row.name == name) return row;
    rows.push_back({name, kind, unit, {}});
    return rows.back();
  }

  StrategyResult result_;
};

// "[#####     ] 12/20 frames" redrawn in place on a terminal; occasional lines otherwise.
class Progress {
 public:
  Progress(int total, bool terminal, std::string unit = "frames")
      : total_(total), terminal_(terminal), unit_(std::move(unit)) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress() { finish(); }

  void update(int done, const std::string& label) {
    if (total_ <= 0) return;
    if (terminal_) {
      const auto now = std::chrono::steady_clock::now();
      // Redrawing a few times a second is enough; the last frame is always shown.
      if (drawn_ && done < total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
      last_draw_ = now;
      constexpr int kBarWidth = 30;
      const int filled = static_cast<int>(static_cast<long long>(done) * kBarWidth / total_);
      std::string line = "\r[" + std::string(static_cast<size_t>(filled), '#') +
                         std::string(static_cast<size_t>(kBarWidth - filled), ' ') + "] " + std::to_string(done) +
                         "/" + std::to_string(total_) + " " + unit_ + " (" + label + ")";
      const size_t visible = line.size() - 1;
      if (visible < width_) line.append(width_ - visible, ' ');
      width_ = std::max(width_, visible);
      std::fputs(line.c_str(), stderr);
      std::fflush(stderr);
      drawn_ = true;
    } else {
      // A line per quarter; short runs only say when they are done.
      const int quarter = static_cast<int>(static_cast<long long>(done) * 4 / total_);
      if (quarter <= last_quarter_ || (total_ < 8 && done < total_)) return;
      last_quarter_ = quarter;
      std::fprintf(stderr, "%s: %d/%d %s (%s)\n", kProgram, done, total_, unit_.c_str(), label.c_str());
    }
  }

  // Clears the bar so that what follows (the summary, an error) starts on a clean line.
  void finish() {
    if (!terminal_ || !drawn_) return;
    std::string blank(1, '\r');
    blank.append(width_, ' ');
    blank += '\r';
    std::fputs(blank.c_str(), stderr);
    std::fflush(stderr);
    drawn_ = false;
  }

 private:
  int total_;
  bool terminal_;
  std::string unit_;
  bool drawn_ = false;
  size_t width_ = 0;
  int last_quarter_ = 0;
  std::chrono::steady_clock::time_point last_draw_{};
};

// ---------------------------------------------------------------------------------------------
// Output

std::string format_value(double value, Unit unit) { return cli::format_fixed(value, unit_decimals(unit)); }

void print_table(const StrategyResult& result, const BenchOptions& options) {
  std::printf("\nsort %s: %d frames after %d warm-up\n", result.sort.c_str(), options.repeat, options.warmup);
  size_t name_width = 20;
  for (const auto* rows : {&result.passes, &result.frame})
    for (const auto& row : *rows) name_width = std::max(name_width, row.name.size());
  const int width = static_cast<int>(name_width);
  std::printf("  %-*s %-4s %12s %12s %12s\n", width, "metric", "unit", "median", "min", "max");
  for (const auto* rows : {&result.passes, &result.frame}) {
    for (const auto& row : *rows) {
      const Summary summary = summarize(row.samples);
      std::printf("  %-*s %-4s %12s %12s %12s\n", width, row.name.c_str(), unit_name(row.unit),
                  format_value(summary.median, row.unit).c_str(), format_value(summary.min, row.unit).c_str(),
                  format_value(summary.max, row.unit).c_str());
    }
  }
}

double median_gpu_frame(const StrategyResult& result) {
  for (const auto& row : result.frame)
    if (row.name == "gpu frame") return summarize(row.samples).median;
  return 0;
}

void print_comparison(const std::vector<StrategyResult>& results) {
  if (results.size() < 2) return;
  size_t fastest = 0;
  for (size_t i = 1; i < results.size(); ++i)
    if (median_gpu_frame(results[i]) < median_gpu_frame(results[fastest])) fastest = i;
  std::printf("\nsort comparison (median gpu frame):\n");
  for (size_t i = 0; i < results.size(); ++i)
    std::printf("  %-20s %12s ms%s\n", results[i].sort.c_str(),
                cli::format_fixed(median_gpu_frame(results[i]), 3).c_str(), i == fastest ? "  (fastest)" : "");
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

// Exact for counts (integers up to 2^53), 9 significant digits otherwise; null when not finite.
std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[64];
  if (value == std::floor(value) && std::fabs(value) < 9007199254740992.0)
    std::snprintf(buffer, sizeof buffer, "%.0f", value);
  else
    std::snprintf(buffer, sizeof buffer, "%.9g", value);
  return buffer;
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (byte < 0x20) {
          char escape[8];
          std::snprintf(escape, sizeof escape, "\\u%04x", unsigned(byte));
          out += escape;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

struct RunInfo {
  std::string scene_path;
  std::string scene_description;
  uint64_t gaussians = 0;
  int sh_degree = 0;
  std::string camera;
  int width = 0;
  int height = 0;
  tilesplat::DeviceInfo device;
};

std::string make_csv(const std::vector<StrategyResult>& results, const RunInfo& info) {
  std::string csv = "device,scene,width,height,sort,kind,metric,unit,median,min,max,samples\n";
  for (const auto& result : results) {
    for (const auto* rows : {&result.passes, &result.frame}) {
      for (const auto& row : *rows) {
        const Summary summary = summarize(row.samples);
        csv += csv_field(info.device.name) + "," + csv_field(info.scene_path) + "," + std::to_string(info.width) +
               "," + std::to_string(info.height) + "," + csv_field(result.sort) + "," + row.kind + "," +
               csv_field(row.name) + "," + unit_name(row.unit) + "," + json_number(summary.median) + "," +
               json_number(summary.min) + "," + json_number(summary.max) + "," +
               std::to_string(row.samples.size()) + "\n";
      }
    }
  }
  return csv;
}

std::string make_json(const std::vector<StrategyResult>& results, const RunInfo& info,
                      const BenchOptions& options) {
  std::string json = "{\n";
  json += "  \"tool\": \"tilesplat-bench\",\n";
  json += "  \"scene\": {\"path\": " + json_string(info.scene_path) + ", \"gaussians\": " +
          json_number(double(info.gaussians)) + ", \"sh_degree\": " + std::to_string(info.sh_degree) + "},\n";
  json += "  \"camera\": {\"description\": " + json_string(info.camera) + ", \"width\": " +
          std::to_string(info.width) + ", \"height\": " + std::to_string(info.height) + "},\n";
  json += "  \"device\": {\"name\": " + json_string(info.device.name) + ", \"driver\": " +
          json_string(info.device.driver) + ", \"subgroup_size\": " + std::to_string(info.device.subgroup_size) +
          ", \"timestamp_period_ns\": " + json_number(info.device.timestamp_period_ns) + "},\n";
  json += "  \"warmup\": " + std::to_string(options.warmup) + ",\n";
  json += "  \"repeat\": " + std::to_string(options.repeat) + ",\n";
  json += "  \"results\": [";
  for (size_t r = 0; r < results.size(); ++r) {
    const auto& result = results[r];
    json += r ? ",\n" : "\n";
    json += "    {\n      \"sort\": " + json_string(result.sort) + ",\n      \"metrics\": [";
    bool first = true;
    for (const auto* rows : {&result.passes, &result.frame}) {
      for (const auto& row : *rows) {
        const Summary summary = summarize(row.samples);
        json += first ? "\n" : ",\n";
        first = false;
        json += "        {\"name\": " + json_string(row.name) + ", \"kind\": \"" + row.kind + "\", \"unit\": \"" +
                unit_name(row.unit) + "\", \"median\": " + json_number(summary.median) +
                ", \"min\": " + json_number(summary.min) + ", \"max\": " + json_number(summary.max) +
                ", \"samples\": [";
        for (size_t i = 0; i < row.samples.size(); ++i) json += (i ? ", " : "") + json_number(row.samples[i]);
        json += "]}";
      }
    }
    json += "\n      ]\n    }";
  }
  json += "\n  ]\n}\n";
  return json;
}

// ---------------------------------------------------------------------------------------------

std::vector<int> parse_int_list(std::string_view flag, const std::string& text, int min, int max) {
  std::vector<int> values;
  for (const auto& part : cli::split(text, ',')) {
    const int value = cli::parse_int(flag, part, min, max);
    if (std::find(values.begin(), values.end(), value) == values.end()) values.push_back(value);
  }
  if (values.empty()) throw cli::UsageError(std::string(flag) + " needs at least one value");
  return values;
}

void add_bench_options(cli::ArgParser& parser, BenchOptions& options) {
  cli::add_common_options(parser, options.common, cli::SortChoice::kList);

  parser.section("benchmark");
  parser.add_int("--warmup", "N", "frames rendered and discarded before measuring, per sort (default 2)",
                 &options.warmup, 0, 1000000);
  parser.add_int("--repeat", "N", "frames measured per sort (default 10)", &options.repeat, 1, 1000000);
  parser.add_string("--csv", "FILE.csv", "also write the results as CSV: one row per sort and metric",
                    &options.csv);
  parser.add_string("--json", "FILE.json", "also write the results, every sample included, as JSON",
                    &options.json);

  parser.section("sort micro-benchmark");
  parser.add_switch("--sort-bench",
                    "time the sort strategies alone on random keys (no SCENE), with std::sort and a CPU "
                    "radix sort on the same keys for comparison; --warmup and --repeat count sorts",
                    &options.sort_bench);
  parser.add_value("--sort-sizes", "E[,E...]",
                   "key counts as powers of two, each 0 to 26 (default 10,12,14,16,18,20,22,24)",
                   [&options](const std::string& text) { options.sort_sizes = parse_int_list("--sort-sizes", text, 0, 26); });
  parser.add_value("--key-bits", "B[,B...]", "key widths in bits, each 1 to 64 (default 32,64)",
                   [&options](const std::string& text) { options.key_bits = parse_int_list("--key-bits", text, 1, 64); });
}

// Writes the --csv and --json files that were asked for, warns about validation messages, and
// returns " -> a.csv, b.json" for the closing line.
template <typename MakeCsv, typename MakeJson>
std::string write_result_files(const BenchOptions& options, MakeCsv make_csv_text, MakeJson make_json_text,
                               const tilesplat::Renderer& renderer) {
  std::string written;
  if (!options.csv.empty()) {
    cli::write_file_atomic(options.csv, make_csv_text());
    written += " -> " + options.csv;
  }
  if (!options.json.empty()) {
    cli::write_file_atomic(options.json, make_json_text());
    written += (written.empty() ? " -> " : ", ") + options.json;
  }
  if (const auto messages = renderer.validation_messages(); messages > 0)
    cli::print_warning(kProgram, std::to_string(messages) + " Vulkan validation messages (see above)");
  return written;
}

// ---------------------------------------------------------------------------------------------
// The sort micro-benchmark: keys per second against key count, per strategy and key width, with
// the CPU sorts measured in the same run so that every figure is also a ratio on this machine.

struct SortRow {
  int key_bits = 0;
  uint64_t keys = 0;
  std::string sorter;
  std::string where;  // "gpu" (GPU timestamps of the sort alone) or "cpu" (wall clock, one thread)
  std::vector<double> ms;
};

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

double median_ms(const SortRow& row) { return summarize(row.ms).median; }

std::string make_sort_csv(const std::vector<SortRow>& rows, const tilesplat::DeviceInfo& device) {
  std::string csv = "device,key_bits,keys,sorter,where,median_ms,min_ms,max_ms,mkeys_per_s,vs_std_sort,samples\n";
  for (const auto& row : rows) {
    const Summary s = summarize(row.ms);
    double std_ms = 0;
    for (const auto& other : rows)
      if (other.key_bits == row.key_bits && other.keys == row.keys && other.sorter == "std::sort")
        std_ms = median_ms(other);
    csv += csv_field(device.name) + "," + std::to_string(row.key_bits) + "," + std::to_string(row.keys) + "," +
           csv_field(row.sorter) + "," + row.where + "," + json_number(s.median) + "," + json_number(s.min) + "," +
           json_number(s.max) + "," + json_number(s.median > 0 ? double(row.keys) / s.median / 1e3 : 0) + "," +
           json_number(s.median > 0 ? std_ms / s.median : 0) + "," + std::to_string(row.ms.size()) + "\n";
  }
  return csv;
}

std::string make_sort_json(const std::vector<SortRow>& rows, const tilesplat::DeviceInfo& device,
                           const BenchOptions& options) {
  std::string json = "{\n  \"tool\": \"tilesplat-bench --sort-bench\",\n";
  json += "  \"device\": {\"name\": " + json_string(device.name) + ", \"driver\": " + json_string(device.driver) +
          ", \"subgroup_size\": " + std::to_string(device.subgroup_size) + "},\n";
  json += "  \"warmup\": " + std::to_string(options.warmup) + ",\n  \"repeat\": " + std::to_string(options.repeat) +
          ",\n  \"results\": [";
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    const Summary s = summarize(row.ms);
    json += i ? ",\n" : "\n";
    json += "    {\"key_bits\": " + std::to_string(row.key_bits) + ", \"keys\": " + std::to_string(row.keys) +
            ", \"sorter\": " + json_string(row.sorter) + ", \"where\": \"" + row.where +
            "\", \"median_ms\": " + json_number(s.median) + ", \"min_ms\": " + json_number(s.min) +
            ", \"max_ms\": " + json_number(s.max) + ", \"samples_ms\": [";
    for (size_t k = 0; k < row.ms.size(); ++k) json += (k ? ", " : "") + json_number(row.ms[k]);
    json += "]}";
  }
  json += "\n  ]\n}\n";
  return json;
}

int run_sort_bench(const cli::ArgParser& parser, const BenchOptions& options) {
  if (!options.common.scene.empty())
    throw cli::UsageError("--sort-bench sorts random keys and takes no SCENE");
  for (const char* flag : {"--cameras", "--view", "--width", "--height", "--azimuth", "--elevation", "--fov",
                           "--distance", "--strict"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --sort-bench");
  cli::check_distinct_paths({{"--csv", options.csv}, {"--json", options.json}});
  if (!options.csv.empty()) cli::check_output_path(options.csv, "--csv");
  if (!options.json.empty()) cli::check_output_path(options.json, "--json");

  std::vector<std::string> sorts = options.common.sorts;
  if (sorts.empty()) sorts = tilesplat::sort_strategies();
  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  const tilesplat::DeviceInfo device = renderer->device_info();
  std::printf("device  %s (driver %s), subgroup size %u\n", device.name.c_str(), device.driver.c_str(),
              device.subgroup_size);
  std::printf("sorts   %d warm-up + %d measured per row; GPU rows time the sort alone (timestamps), CPU rows\n"
              "        are one thread of this machine's CPU; every GPU result is checked against the CPU radix sort\n",
              options.warmup, options.repeat);
  std::fflush(stdout);

  const int runs_per_row = options.warmup + options.repeat;
  const int rows_per_case = int(sorts.size()) + 2;
  const int total = runs_per_row * rows_per_case * int(options.key_bits.size() * options.sort_sizes.size());
  std::vector<SortRow> rows;
  const auto start = std::chrono::steady_clock::now();
  {
    Progress progress(total, cli::stderr_is_terminal(), "sorts");
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
          for (int run = 0; run < runs_per_row; ++run) {
            const auto result = renderer->sort_keys(sort, keys, uint32_t(bits));
            if (run == 0 && result.order != expected) {
              progress.finish();
              throw std::runtime_error("sort strategy '" + sort + "' gave a different order than the CPU radix "
                                       "sort on " + label);
            }
            if (run >= options.warmup) row.ms.push_back(result.gpu_ms);
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

  std::printf("\n  %4s %10s  %-12s %-4s %12s %12s %12s\n", "bits", "keys", "sorter", "on", "median ms",
              "Mkeys/s", "vs std::sort");
  for (const auto& row : rows) {
    double std_ms = 0;
    for (const auto& other : rows)
      if (other.key_bits == row.key_bits && other.keys == row.keys && other.sorter == "std::sort")
        std_ms = median_ms(other);
    const double ms = median_ms(row);
    std::printf("  %4d %10llu  %-12s %-4s %12s %12s %11sx\n", row.key_bits, static_cast<unsigned long long>(row.keys),
                row.sorter.c_str(), row.where.c_str(), cli::format_fixed(ms, 3).c_str(),
                cli::format_fixed(ms > 0 ? double(row.keys) / ms / 1e3 : 0, 2).c_str(),
                cli::format_fixed(ms > 0 ? std_ms / ms : 0, 2).c_str());
  }
  std::fflush(stdout);

  const std::string written = write_result_files(
      options, [&] { return make_sort_csv(rows, device); }, [&] { return make_sort_json(rows, device, options); },
      *renderer);
  std::fprintf(stderr, "%s: sort micro-benchmark, %d sorts in %s s%s\n", kProgram, total,
               cli::format_fixed(seconds, 2).c_str(), written.c_str());
  return cli::kExitOk;
}

int run(int argc, char** argv) {
  BenchOptions options;
  cli::ArgParser parser(kProgram, "tilesplat-bench SCENE.ply [options]",
                        "Renders a view of a 3D Gaussian Splatting scene repeatedly and prints the GPU time "
                        "of every pass (median, min, max over the measured frames) for each sort strategy, "
                        "with the frame's visible Gaussians, intersections and device memory.");
  add_bench_options(parser, options);
  if (cli::parse_and_handle_info_flags(parser, argc, argv, options.common)) return cli::kExitOk;
  if (options.sort_bench) return run_sort_bench(parser, options);
  for (const char* flag : {"--sort-sizes", "--key-bits"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " applies only with --sort-bench");
  cli::check_common_options(parser, options.common);
  cli::check_distinct_paths({{"SCENE", options.common.scene},
                             {"--cameras", options.common.cameras},
                             {"--csv", options.csv},
                             {"--json", options.json}});
  if (!options.csv.empty()) cli::check_output_path(options.csv, "--csv");
  if (!options.json.empty()) cli::check_output_path(options.json, "--json");

  std::vector<std::string> sorts = options.common.sorts;
  if (sorts.empty()) sorts = tilesplat::sort_strategies();
  if (sorts.empty()) sorts = {tilesplat::RenderSettings{}.sort};

  const cli::LoadedScene loaded = cli::load_scene_and_camera(options.common, kProgram);
  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  renderer->set_scene(loaded.scene);

  RunInfo info;
  info.scene_path = loaded.path.string();
  info.scene_description = cli::describe_scene(loaded.scene);
  info.gaussians = loaded.scene.size();
  info.sh_degree = loaded.scene.sh_degree;
  info.camera = loaded.camera_description;
  info.width = loaded.camera.width;
  info.height = loaded.camera.height;
  info.device = renderer->device_info();

  std::printf("scene   %s: %s, loaded in %s ms\n", loaded.path.filename().string().c_str(),
              info.scene_description.c_str(), cli::format_fixed(loaded.load_ms, 1).c_str());
  std::printf("camera  %s, %dx%d\n", info.camera.c_str(), info.width, info.height);
  std::printf("device  %s (driver %s), subgroup size %u\n", info.device.name.c_str(), info.device.driver.c_str(),
              info.device.subgroup_size);
  std::fflush(stdout);

  const int frames_per_sort = options.warmup + options.repeat;
  const int total_frames = frames_per_sort * static_cast<int>(sorts.size());
  const auto start = std::chrono::steady_clock::now();
  std::vector<StrategyResult> results;
  {
    Progress progress(total_frames, cli::stderr_is_terminal());
    int done = 0;
    for (const auto& sort : sorts) {
      tilesplat::RenderSettings settings;
      settings.sort = sort;
      Collector collector(sort);
      for (int frame = 0; frame < frames_per_sort; ++frame) {
        // The image itself is not needed; rendering reads it back, which is part of cpu frame.
        (void)renderer->render(loaded.camera, settings);
        if (frame >= options.warmup) collector.add(renderer->last_frame_stats());
        progress.update(++done, sort);
      }
      results.push_back(collector.take());
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  for (const auto& result : results) print_table(result, options);
  print_comparison(results);
  std::fflush(stdout);

  const std::string written = write_result_files(
      options, [&] { return make_csv(results, info); }, [&] { return make_json(results, info, options); },
      *renderer);
  std::fprintf(stderr, "%s: %s, %s, %dx%d, %d frames in %s s%s\n", kProgram,
               loaded.path.filename().string().c_str(), info.scene_description.c_str(), info.width, info.height,
               total_frames, cli::format_fixed(seconds, 2).c_str(), written.c_str());
  return cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
