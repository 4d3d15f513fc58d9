// tilesplat-bench: times the renderer's passes over repeated frames, per sort strategy.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli.h"
#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

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
  Progress(int total, bool terminal) : total_(total), terminal_(terminal) {}
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
                         "/" + std::to_string(total_) + " frames (" + label + ")";
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
      std::fprintf(stderr, "%s: %d/%d frames (%s)\n", kProgram, done, total_, label.c_str());
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
}

int run(int argc, char** argv) {
  BenchOptions options;
  cli::ArgParser parser(kProgram, "tilesplat-bench SCENE.ply [options]",
                        "Renders a view of a 3D Gaussian Splatting scene repeatedly and prints the GPU time "
                        "of every pass (median, min, max over the measured frames) for each sort strategy, "
                        "with the frame's visible Gaussians, intersections and device memory.");
  add_bench_options(parser, options);
  if (cli::parse_and_handle_info_flags(parser, argc, argv, options.common)) return cli::kExitOk;
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

  std::string written;
  if (!options.csv.empty()) {
    cli::write_file_atomic(options.csv, make_csv(results, info));
    written += " -> " + options.csv;
  }
  if (!options.json.empty()) {
    cli::write_file_atomic(options.json, make_json(results, info, options));
    written += (written.empty() ? " -> " : ", ") + options.json;
  }
  if (const auto messages = renderer->validation_messages(); messages > 0)
    cli::print_warning(kProgram, std::to_string(messages) + " Vulkan validation messages (see above)");
  std::fprintf(stderr, "%s: %s, %s, %dx%d, %d frames in %s s%s\n", kProgram,
               loaded.path.filename().string().c_str(), info.scene_description.c_str(), info.width, info.height,
               total_frames, cli::format_fixed(seconds, 2).c_str(), written.c_str());
  return cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
