// tilesplat-bench: times the renderer's passes over repeated frames, per scene, image size, camera
// and sort strategy; or, with --sort-bench, the sort strategies alone on random keys against CPU
// sorts on the same keys.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "accuracy_report.h"
#include "bench_plot.h"
#include "cli.h"
#include "effects_report.h"
#include "formats_report.h"
#include "scaling_report.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/sort.h"
#include "tilesplat/version.h"

namespace {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;
namespace plot = tilesplat::plot;

constexpr const char* kProgram = "tilesplat-bench";

struct BenchOptions {
  cli::CommonOptions common;
  int warmup = 2;
  int repeat = 10;
  std::string csv;
  std::string json;
  std::string plot;
  std::vector<cli::ImageSize> resolutions;  // --resolutions; empty: the one size of --width/--height
  std::vector<int> views;                   // --views; empty: --view alone (or every view, with all_views)
  bool all_views = false;
  int orbit = 0;  // --orbit N: N orbit cameras; 0: the one at --azimuth
  bool sort_bench = false;
  bool accuracy = false;  // --accuracy: the error/time report
  bool effects = false;   // --effects: the per-effect cost table
  bool formats = false;   // --formats: what each file of a scene costs against its lossless PLY
  bool scaling = false;   // --scaling: frame time and memory against Gaussian count and image size
  int tile_copies = 0;    // --tile-copies N: with --scaling, also N copies of the largest scene
  std::string markdown;
  tilesplat::accuracy::CameraPath path = tilesplat::accuracy::CameraPath::kPan;
  int path_frames = 6;
  double path_step = 0.0005;
  double consistency_angle = 0.08;
  std::vector<int> sort_sizes{10, 12, 14, 16, 18, 20, 22, 24};  // log2 of the key counts
  std::vector<int> key_bits{32, 64};
  std::string command;  // the command as typed, recorded in every output
};

enum class Unit { kMilliseconds, kCount, kMebibytes, kDecibels, kColour };  // kColour: a difference, 1 = white

const char* unit_name(Unit unit) {
  switch (unit) {
    case Unit::kMilliseconds: return "ms";
    case Unit::kCount: return "";
    case Unit::kMebibytes: return "MiB";
    case Unit::kDecibels: return "dB";
    case Unit::kColour: return "";
  }
  return "";
}

int unit_decimals(Unit unit) {
  switch (unit) {
    case Unit::kMilliseconds: return 3;
    case Unit::kCount: return 0;
    case Unit::kMebibytes: return 2;
    case Unit::kDecibels: return 2;
    case Unit::kColour: return 6;
  }
  return 3;
}

// One row of the table: a metric sampled once per measured frame (or, in a summary over the views
// of a camera path, once per view).
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
  summary.min = *std::min_element(samples.begin(), samples.end());
  summary.max = *std::max_element(samples.begin(), samples.end());
  summary.median = cli::median(std::move(samples));
  return summary;
}

struct StrategyResult {
  std::string sort;
  std::vector<Series> passes;  // in frame order (of first appearance)
  std::vector<Series> frame;   // gpu frame, cpu frame, counts, memory
};

Series& find_series(std::vector<Series>& rows, const std::string& name, const std::string& kind, Unit unit) {
  for (auto& row : rows)
    if (row.name == name) return row;
  rows.push_back({name, kind, unit, {}});
  return rows.back();
}

const Series* find_series(const std::vector<Series>& rows, const std::string& name) {
  for (const auto& row : rows)
    if (row.name == name) return &row;
  return nullptr;
}

double median_of(const std::vector<Series>& rows, const std::string& name) {
  const Series* row = find_series(rows, name);
  return row ? summarize(row->samples).median : 0;
}

// Gathers FrameStats of the measured frames into per-metric series.
// Every exact strategy must give the same image to the bit; a quantizing one (cpu-radix16) may
// not, and what that costs in accuracy is reported next to its time: the largest RGB difference
// from the first exact strategy's image (0 when identical) and, when they differ, the PSNR.
constexpr const char* kImageMaxAbs = "image max abs vs exact";
constexpr const char* kImagePsnr = "image psnr vs exact";

void record_image_agreement(std::vector<StrategyResult>& results, const std::vector<tilesplat::RenderImage>& images) {
  size_t reference = results.size();
  for (size_t i = 0; i < results.size() && reference == results.size(); ++i)
    if (tilesplat::sort_strategy_is_exact(results[i].sort)) reference = i;
  if (reference == results.size() || images.size() != results.size()) return;
  for (size_t i = 0; i < results.size(); ++i) {
    const tilesplat::ImageDifference diff = tilesplat::compare_images(images[i], images[reference]);
    find_series(results[i].frame, kImageMaxAbs, "frame", Unit::kColour).samples.push_back(diff.max_abs);
    if (diff.max_abs > 0)
      find_series(results[i].frame, kImagePsnr, "frame", Unit::kDecibels).samples.push_back(diff.psnr_db);
    if (tilesplat::sort_strategy_is_exact(results[i].sort) && diff.max_abs > 0)
      std::fprintf(stderr, "warning: exact sort strategies '%s' and '%s' gave different images (max abs %g)\n",
                   results[i].sort.c_str(), results[reference].sort.c_str(), diff.max_abs);
  }
}

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
      find_series(result_.passes, label, "pass", Unit::kMilliseconds).samples.push_back(pass.gpu_ms);
    }
    add_frame("gpu frame", Unit::kMilliseconds, stats.gpu_ms);
    add_frame("cpu frame", Unit::kMilliseconds, stats.cpu_ms);
    add_frame("visible gaussians", Unit::kCount, double(stats.visible));
    add_frame("intersections", Unit::kCount, double(stats.intersections));
    add_frame("sort bits", Unit::kCount, double(stats.sort_bits));
    add_frame("retries", Unit::kCount, double(stats.retries));
    add_frame("sort fallbacks", Unit::kCount, double(stats.sort_fallbacks));
    add_frame("device memory", Unit::kMebibytes, double(stats.device_bytes) / (1024.0 * 1024.0));
  }

  StrategyResult take() { return std::move(result_); }

 private:
  void add_frame(const char* name, Unit unit, double value) {
    find_series(result_.frame, name, "frame", unit).samples.push_back(value);
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
// The frame benchmark's plan: every scene loaded once, with the cameras of its path at every size.

struct BenchScene {
  cli::LoadedScene loaded;  // the camera fields are unused: the cameras are in the run's cases
  std::string name;         // the file name
  std::string description;  // "31,000 Gaussians (SH2)"
  uint64_t gaussians = 0;   // kept apart from loaded.scene, which is released once the scene is measured
  int sh_degree = 0;
  std::string cameras;      // --cameras for this scene; empty: the scene file's cameras, else an orbit
};

// Where the scene's cameras come from, for the JSON: --cameras, the scene file's own, or null (orbit).
std::string cameras_source(const BenchScene& scene) {
  if (!scene.cameras.empty()) return scene.cameras;
  const cli::SceneViews own = cli::scene_views(scene.loaded);
  return own.views.empty() ? std::string() : own.file.string();
}

// One camera of the run, a row of the results per sort strategy.
struct Case {
  size_t scene = 0;        // index into the scenes
  size_t size = 0;         // index into the run's sizes
  std::string view_label;  // short: "view 2", "azimuth 120.0"
  cli::NamedCamera camera;
  std::vector<StrategyResult> results;  // one per sort, in --sort order
};

// The cases of one scene at one size (all the views of its path), and per sort strategy the
// statistics over those views of each view's median.
struct Group {
  std::vector<const Case*> cases;
  std::vector<StrategyResult> over_views;
};

std::string size_of(const Case& c) { return cli::format_size(c.camera.camera.width, c.camera.camera.height); }

// "320x180"; without --resolutions or --width/--height, views of a cameras.json keep their own sizes,
// which need not agree.
std::string size_label(const Group& group) {
  const std::string first = size_of(*group.cases.front());
  for (const Case* c : group.cases)
    if (size_of(*c) != first) return "each view's own size";
  return first;
}

std::string orbit_label(double azimuth_deg) { return "azimuth " + cli::format_fixed(azimuth_deg, 1); }

// The cameras of one scene: views of its cameras.json, or orbit positions evenly spaced in azimuth,
// each at every size. Out-of-range views and sizes fail here, before anything is measured.
std::vector<Case> plan_cases(const BenchOptions& options, const BenchScene& scene, size_t scene_index,
                             const std::vector<cli::ImageSize>& sizes) {
  std::vector<Case> cases;
  auto add = [&](size_t size_index, std::string label, cli::NamedCamera camera) {
    cases.push_back({scene_index, size_index, std::move(label), std::move(camera), {}});
  };
  const cli::SceneViews own = cli::scene_views(scene.loaded);
  if (!scene.cameras.empty() || !own.views.empty()) {
    const auto file_views = scene.cameras.empty() ? own.views : cli::load_camera_views(scene.cameras);
    const fs::path views_file = scene.cameras.empty() ? own.file : fs::path(scene.cameras);
    if (scene.cameras.empty() && (options.orbit > 0 || options.common.orbit_given))
      throw cli::UsageError("--orbit, --azimuth, --elevation, --fov and --distance apply only to orbit cameras, and '" +
                            scene.loaded.path.string() + "' has cameras of its own (pick them with --view or --views)");
    std::vector<int> indices = options.views;
    if (options.all_views) {
      indices.resize(file_views.size());
      std::iota(indices.begin(), indices.end(), 0);
    } else if (indices.empty()) {
      indices = {options.common.view};
    }
    const char* flag = options.views.empty() && !options.all_views ? "--view" : "--views";
    for (size_t s = 0; s < sizes.size(); ++s)
      for (const int index : indices)
        add(s, "view " + std::to_string(index),
            cli::view_camera(file_views, index, views_file, sizes[s].width, sizes[s].height, flag));
  } else {
    if (!options.views.empty() || options.all_views || options.common.view_given)
      throw cli::UsageError(std::string(options.common.view_given ? "--view" : "--views") + " needs cameras: '" +
                            scene.loaded.path.string() +
                            "' has none, and no --cameras FILE.json was given (without them the cameras orbit it)");
    const int count = std::max(1, options.orbit);
    for (size_t s = 0; s < sizes.size(); ++s) {
      for (int v = 0; v < count; ++v) {
        tilesplat::OrbitParams orbit = options.common.orbit;
        orbit.azimuth_deg = std::fmod(orbit.azimuth_deg + 360.0 * v / count, 360.0);
        add(s, orbit_label(orbit.azimuth_deg),
            cli::orbit_view(scene.loaded, sizes[s].width, sizes[s].height, orbit));
      }
    }
  }
  return cases;
}

// Per metric, one sample per view: that view's median. Summarized, they give the median, min and
// max over the views of a path.
StrategyResult over_views(const std::vector<const Case*>& cases, size_t sort) {
  StrategyResult summary;
  summary.sort = cases.front()->results[sort].sort;
  for (const Case* c : cases) {
    const StrategyResult& result = c->results[sort];
    for (const auto& row : result.passes)
      find_series(summary.passes, row.name, row.kind, row.unit).samples.push_back(summarize(row.samples).median);
    for (const auto& row : result.frame)
      find_series(summary.frame, row.name, row.kind, row.unit).samples.push_back(summarize(row.samples).median);
  }
  return summary;
}

std::vector<Group> group_cases(const std::vector<Case>& cases, size_t sort_count) {
  std::vector<Group> groups;
  for (const auto& c : cases) {
    if (groups.empty() || groups.back().cases.front()->scene != c.scene ||
        groups.back().cases.front()->size != c.size)
      groups.emplace_back();
    groups.back().cases.push_back(&c);
  }
  for (auto& group : groups)
    for (size_t sort = 0; sort < sort_count; ++sort) group.over_views.push_back(over_views(group.cases, sort));
  return groups;
}

// ---------------------------------------------------------------------------------------------
// Output

std::string format_value(double value, Unit unit) { return cli::format_fixed(value, unit_decimals(unit)); }

void print_table(const StrategyResult& result, const std::string& heading) {
  std::printf("\nsort %s: %s\n", result.sort.c_str(), heading.c_str());
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

void print_comparison(const std::vector<StrategyResult>& results, const std::string& what) {
  if (results.size() < 2) return;
  size_t fastest = 0;
  for (size_t i = 1; i < results.size(); ++i)
    if (median_of(results[i].frame, "gpu frame") < median_of(results[fastest].frame, "gpu frame")) fastest = i;
  std::printf("\nsort comparison (%s):\n", what.c_str());
  for (size_t i = 0; i < results.size(); ++i)
    std::printf("  %-20s %12s ms%s\n", results[i].sort.c_str(),
                cli::format_fixed(median_of(results[i].frame, "gpu frame"), 3).c_str(),
                i == fastest ? "  (fastest)" : "");
}

// "(51.258..52.382)"
std::string min_max(const Summary& summary) {
  std::string text = "(";
  text += cli::format_fixed(summary.min, 3) + ".." + cli::format_fixed(summary.max, 3) + ")";
  return text;
}

// One group on stdout. A single camera gets the full table per sort; a path of several gets a line
// per view and sort, then the full tables over the views, so that it stays readable at any length.
void print_group(const Group& group, const BenchScene& scene, const BenchOptions& options) {
  const std::string frames =
      std::to_string(options.repeat) + " frames after " + std::to_string(options.warmup) + " warm-up";
  if (group.cases.size() == 1) {
    const Case& c = *group.cases.front();
    std::printf("\n== %s at %s, %s ==\n", scene.name.c_str(), size_label(group).c_str(),
                c.camera.description.c_str());
    for (const auto& result : c.results) print_table(result, frames);
    print_comparison(c.results, "median gpu frame");
    return;
  }

  const size_t views = group.cases.size();
  std::printf("\n== %s at %s: %zu views, %s each ==\n", scene.name.c_str(), size_label(group).c_str(), views,
              frames.c_str());
  size_t label_width = 8;
  for (const Case* c : group.cases) label_width = std::max(label_width, c->view_label.size());
  const int lw = static_cast<int>(label_width);
  std::printf("  %-*s %-12s %12s  %-20s %12s %14s\n", lw, "view", "sort", "gpu frame ms", "(min..max)", "cpu ms",
              "intersections");
  for (const Case* c : group.cases) {
    for (const auto& result : c->results) {
      const Series* gpu = find_series(result.frame, "gpu frame");
      const Summary s = gpu ? summarize(gpu->samples) : Summary{};
      std::printf("  %-*s %-12s %12s  %-20s %12s %14s\n", lw, c->view_label.c_str(), result.sort.c_str(),
                  cli::format_fixed(s.median, 3).c_str(), min_max(s).c_str(),
                  cli::format_fixed(median_of(result.frame, "cpu frame"), 3).c_str(),
                  cli::format_fixed(median_of(result.frame, "intersections"), 0).c_str());
    }
  }
  const std::string over = "median, min and max over the " + std::to_string(views) + " views of each view's median";
  for (const auto& summary : group.over_views) print_table(summary, over);
  print_comparison(group.over_views, "median over the views of the median gpu frame");
}

// A CSV number: exact for counts (integers up to 2^53), 9 significant digits otherwise; "null" when
// not finite, as the JSON says.
std::string number_text(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[64];
  if (value == std::floor(value) && std::fabs(value) < 9007199254740992.0)
    std::snprintf(buffer, sizeof buffer, "%.0f", value);
  else
    std::snprintf(buffer, sizeof buffer, "%.9g", value);
  return buffer;
}

// JSON outputs are built as nlohmann::ordered_json (members in the order written here) and dumped
// once; a value that is not finite becomes null.
using Json = nlohmann::ordered_json;

// A JSON number: a count stays an integer, anything else a double (null when not finite).
Json json_number(double value) {
  if (!std::isfinite(value)) return nullptr;
  if (value == std::floor(value) && std::fabs(value) < 9007199254740992.0) return int64_t(value);
  return value;
}

// The "tilesplat" build and "command" members that every JSON output starts with.
void add_provenance(Json& json, const std::string& tool, const std::string& command) {
  const tilesplat::BuildInfo build = tilesplat::build_info();
  json["tool"] = tool;
  json["tilesplat"] = {
      {"version", build.version}, {"commit", build.git_commit}, {"build_type", build.build_type}};
  json["command"] = command;
}

Json json_device(const tilesplat::DeviceInfo& device) {
  return {{"name", device.name},
          {"driver", device.driver},
          {"subgroup_size", device.subgroup_size},
          {"timestamp_period_ns", json_number(device.timestamp_period_ns)}};
}

// Calls visit(row) for every metric of a result, passes first.
template <typename Visit>
void for_each_metric(const StrategyResult& result, Visit&& visit) {
  for (const auto* rows : {&result.passes, &result.frame})
    for (const auto& row : *rows) visit(row);
}

// One CSV line per metric: the rows of each camera ("frames": statistics over the measured
// frames), then with a path of several views the rows over its views (view "all").
std::string make_csv(const std::vector<Group>& groups, const std::vector<BenchScene>& scenes,
                     const tilesplat::DeviceInfo& device) {
  std::string csv = "device,scene,width,height,view,camera,sort,kind,metric,unit,over,median,min,max,samples\n";
  auto add = [&](const std::string& scene, const std::string& width, const std::string& height,
                 const std::string& view, const std::string& camera, const StrategyResult& result,
                 const char* over) {
    for_each_metric(result, [&](const Series& row) {
      const Summary summary = summarize(row.samples);
      csv += cli::csv_field(device.name) + "," + cli::csv_field(scene) + "," + width + "," + height + "," +
             cli::csv_field(view) + "," + cli::csv_field(camera) + "," + cli::csv_field(result.sort) + "," +
             row.kind + "," + cli::csv_field(row.name) + "," + unit_name(row.unit) + "," + over + "," +
             number_text(summary.median) + "," + number_text(summary.min) + "," + number_text(summary.max) +
             "," + std::to_string(row.samples.size()) + "\n";
    });
  };
  for (const auto& group : groups) {
    const std::string& scene = scenes[group.cases.front()->scene].loaded.path.string();
    for (const Case* c : group.cases)
      for (const auto& result : c->results)
        add(scene, std::to_string(c->camera.camera.width), std::to_string(c->camera.camera.height),
            c->view_label, c->camera.description, result, "frames");
    if (group.cases.size() < 2) continue;
    const Case& first = *group.cases.front();
    const bool one_size = size_label(group) == size_of(first);
    const std::string width = one_size ? std::to_string(first.camera.camera.width) : "";
    const std::string height = one_size ? std::to_string(first.camera.camera.height) : "";
    for (const auto& summary : group.over_views)
      add(scene, width, height, "all", std::to_string(group.cases.size()) + " views", summary, "views");
  }
  return csv;
}

Json json_metrics(const StrategyResult& result, bool with_samples) {
  Json metrics = Json::array();
  for_each_metric(result, [&](const Series& row) {
    const Summary summary = summarize(row.samples);
    Json metric = {{"name", row.name},
                   {"kind", row.kind},
                   {"unit", unit_name(row.unit)},
                   {"median", json_number(summary.median)},
                   {"min", json_number(summary.min)},
                   {"max", json_number(summary.max)}};
    if (with_samples) {
      Json samples = Json::array();
      for (const double sample : row.samples) samples.push_back(json_number(sample));
      metric["samples"] = std::move(samples);
    }
    metrics.push_back(std::move(metric));
  });
  return metrics;
}

// "results": one entry per camera and sort, every sample included; "summaries" (for paths of several
// views, like the CSV's view "all"): per scene, size and sort, the median, min and max over the views
// of each view's median.
std::string make_json(const std::vector<Group>& groups, const std::vector<BenchScene>& scenes,
                      const tilesplat::DeviceInfo& device, const BenchOptions& options) {
  Json json;
  add_provenance(json, "tilesplat-bench", options.command);
  json["device"] = json_device(device);
  json["warmup"] = options.warmup;
  json["repeat"] = options.repeat;
  Json& scene_list = json["scenes"] = Json::array();
  for (const auto& scene : scenes) {
    const std::string cameras = cameras_source(scene);
    scene_list.push_back({{"path", scene.loaded.path.string()},
                          {"gaussians", scene.gaussians},
                          {"sh_degree", scene.sh_degree},
                          {"cameras", cameras.empty() ? Json(nullptr) : Json(cameras)}});
  }
  Json& results = json["results"] = Json::array();
  for (const auto& group : groups)
    for (const Case* c : group.cases)
      for (const auto& result : c->results)
        results.push_back({{"scene", scenes[c->scene].loaded.path.string()},
                           {"width", c->camera.camera.width},
                           {"height", c->camera.camera.height},
                           {"view", c->view_label},
                           {"camera", c->camera.description},
                           {"sort", result.sort},
                           {"metrics", json_metrics(result, true)}});
  Json& summaries = json["summaries"] = Json::array();
  for (const auto& group : groups) {
    if (group.cases.size() < 2) continue;
    const Case& c = *group.cases.front();
    for (const auto& summary : group.over_views)
      summaries.push_back({{"scene", scenes[c.scene].loaded.path.string()},
                           {"size", size_label(group)},
                           {"views", group.cases.size()},
                           {"sort", summary.sort},
                           {"metrics", json_metrics(summary, false)}});
  }
  return json.dump(2) + "\n";
}

template <typename T>
void add_unique(std::vector<T>& items, const T& item) {
  if (std::find(items.begin(), items.end(), item) == items.end()) items.push_back(item);
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

std::string device_line(const tilesplat::DeviceInfo& device) { return device.name + ", " + device.driver; }

// A bar per scene, size and sort; its segments are the passes of the frame stats (the median over
// the views of each view's median), in frame order.
std::string make_frame_svg(const std::vector<Group>& groups, const std::vector<BenchScene>& scenes,
                           const tilesplat::DeviceInfo& device, const BenchOptions& options) {
  plot::StackedBarChart chart;
  std::vector<std::string> scene_names;
  std::vector<std::string> sizes;
  for (const auto& group : groups) {
    add_unique(scene_names, scenes[group.cases.front()->scene].name);
    add_unique(sizes, size_label(group));
    for (const auto& summary : group.over_views)
      for (const auto& pass : summary.passes) add_unique(chart.segments, pass.name);
  }
  chart.title = "GPU time per pass: " + join(scene_names) + " at " + join(sizes);
  std::string cameras;
  if (groups.size() == 1 && groups.front().cases.size() == 1)
    cameras = groups.front().cases.front()->camera.description;
  else
    cameras = "median over each path's views";
  chart.subtitle = device_line(device) + "; " + cameras + "; median of " + std::to_string(options.repeat) +
                   " frames after " + std::to_string(options.warmup) + " warm-up";
  chart.axis_label = "GPU time (ms)";
  for (const auto& group : groups) {
    const Case& first = *group.cases.front();
    std::string heading;
    if (groups.size() > 1) {
      heading = scenes[first.scene].name + ", " + size_label(group);
      heading += group.cases.size() == 1 ? ", " + first.camera.description
                                         : ", " + std::to_string(group.cases.size()) + " views";
    }
    for (const auto& summary : group.over_views) {
      plot::StackedBar bar;
      bar.group = heading;
      bar.label = summary.sort;
      for (const auto& segment : chart.segments) {
        const Series* pass = find_series(summary.passes, segment);
        bar.values.push_back(pass ? summarize(pass->samples).median : 0);
      }
      bar.note = "gpu frame " + cli::format_fixed(median_of(summary.frame, "gpu frame"), 1) + " ms";
      chart.bars.push_back(std::move(bar));
    }
  }
  return plot::stacked_bar_svg(chart);
}

// ---------------------------------------------------------------------------------------------
// Options shared by both modes

std::vector<int> parse_int_list(std::string_view flag, const std::string& text, int min, int max) {
  std::vector<int> values;
  for (const auto& part : cli::split(text, ',')) add_unique(values, cli::parse_int(flag, part, min, max));
  if (values.empty()) throw cli::UsageError(std::string(flag) + " needs at least one value");
  return values;
}

void add_bench_options(cli::ArgParser& parser, BenchOptions& options) {
  cli::add_common_options(parser, options.common, cli::SortChoice::kList, cli::SceneChoice::kList);

  parser.section("camera path and sizes");
  parser.add_value("--views", "N[,N...]|all",
                   "several views of --cameras, comma-separated, or 'all': a row of results per view, then the "
                   "median, min and max over the views of each view's median (default: --view alone)",
                   [&options](const std::string& text) {
                     options.all_views = text == "all";
                     options.views.clear();
                     if (!options.all_views)
                       options.views = parse_int_list("--views", text, 0, std::numeric_limits<int>::max());
                   });
  parser.add_int("--orbit", "N",
                 "N orbit cameras evenly spaced in azimuth, from --azimuth on (0, 360/N, ... by default), "
                 "with --elevation, --fov and --distance as given; not with --cameras",
                 &options.orbit, 1, 3600);
  parser.add_value("--resolutions", "WxH[,WxH...]",
                   "image sizes to measure each camera at, e.g. 1920x1080,1280x720 (instead of --width and "
                   "--height)",
                   [&options](const std::string& text) {
                     options.resolutions = cli::parse_resolutions("--resolutions", text);
                   });

  parser.section("benchmark");
  parser.add_int("--warmup", "N", "frames rendered and discarded before measuring, per camera and sort (default 2)",
                 &options.warmup, 0, 1000000);
  parser.add_int("--repeat", "N",
                 "frames measured per camera and sort (default 10): the median, min and max are over these",
                 &options.repeat, 1, 1000000);
  parser.add_string("--csv", "FILE.csv",
                    "also write the results as CSV: one line per scene, size, view, sort and metric; with several "
                    "views also view 'all', the statistics over the views of each view's median",
                    &options.csv);
  parser.add_string("--json", "FILE.json", "also write the results, every sample included, as JSON",
                    &options.json);
  parser.add_string("--plot", "FILE.svg",
                    "also draw an SVG chart: the median GPU time of each pass as stacked bars, one per scene, "
                    "size and sort; with --sort-bench, Mkeys/s against key count per sort and key width; with "
                    "--accuracy, per scene PSNR against time and, beside it (..._consistency.svg), the view "
                    "inconsistency against time",
                    &options.plot);

  parser.section("accuracy report");
  parser.add_switch("--accuracy",
                    "measure what each accuracy mode costs: per --mode combination (default: each approximation "
                    "alone and the combinations that matter), the GPU time per pass and frame and the error "
                    "against the float64 CPU reference (PSNR, SSIM, max abs) at each view, and the popping "
                    "along a short camera path from the first view (--path) and the view consistency under a turn "
                    "(--consistency-angle); --plot draws the Pareto charts",
                    &options.accuracy);
  parser.add_string(
      "--markdown", "FILE.md",
      "with --accuracy, --effects, --formats or --scaling: also write the report as Markdown tables",
      &options.markdown);
  parser.add_value("--path", "dolly|pan|orbit",
                   "with --accuracy: the camera path the popping is measured on, from the first view: 'pan' "
                   "(turning in place, default), 'orbit' (around the scene centre) or 'dolly' (sideways; "
                   "centre-depth order never changes on it, so the reference cannot pop there)",
                   [&options](const std::string& text) {
                     const auto path = tilesplat::accuracy::parse_camera_path(text);
                     if (!path) throw cli::UsageError("--path: '" + text + "' is not dolly, pan or orbit");
                     options.path = *path;
                   });
  parser.add_int("--path-frames", "N",
                 "with --accuracy: frames of the camera path the popping is measured on (default 6; 0: none)",
                 &options.path_frames, 0, 1000);
  parser.add_value("--consistency-angle", "RAD",
                   "with --accuracy: the view-consistency pair turns the first view in place by RAD radians "
                   "(default 0.08; 0: no pair), rendered at twice its size, and measures what does not follow the "
                   "rotation: the popping per-pixel re-sorting removes",
                   [&options](const std::string& text) {
                     options.consistency_angle = cli::parse_double("--consistency-angle", text);
                     if (!(options.consistency_angle >= 0 && options.consistency_angle <= 0.5))
                       throw cli::UsageError("--consistency-angle: " + text + " is not in [0, 0.5]");
                   });
  parser.add_value("--path-step", "F",
                   "with --accuracy: the path's step per frame: radians for the orbit and the pan, a fraction of "
                   "the distance to the scene centre for the dolly (default 0.0005), in (0, 0.1]",
                   [&options](const std::string& text) {
                     options.path_step = cli::parse_double("--path-step", text);
                     if (!(options.path_step > 0 && options.path_step <= 0.1))
                       throw cli::UsageError("--path-step: " + text + " is not in (0, 0.1]");
                   });

  parser.section("effect costs");
  parser.add_switch("--effects",
                    "measure what each scene effect costs: GPU time per pass with one effect changed at a time "
                    "from all off (SH degree 0..3, relighting, antialiasing modes, depth and splat-count outputs), "
                    "and beside the 'off' rows a scene that never had the effect (SH stored at degree 0, no "
                    "normals); one SCENE, --views or --orbit cameras; --markdown and --csv write the table",
                    &options.effects);

  parser.section("format costs");
  parser.add_switch("--formats",
                    "measure what each file format costs: the first SCENE is the lossless reference (a PLY), the "
                    "others the same scene in other formats; per file its size and bytes per Gaussian, load time "
                    "(median of --repeat loads after --warmup) and peak memory, the largest error of every decoded "
                    "attribute, and the image PSNR and max abs error against the reference's at each view (default: "
                    "the first and the middle view of --cameras, else two orbit views); --markdown, --csv and --plot "
                    "(bytes per Gaussian against PSNR) write the report",
                    &options.formats);

  parser.section("scaling report");
  parser.add_switch(
      "--scaling",
      "measure how the frame's cost and device memory grow: every SCENE from the orbit camera that "
      "frames it at every size of --resolutions (default 960x540,1920x1080,2560x1440,3840x2160), "
      "GPU time per pass, pairs and device memory, then a non-negative least-squares fit of each "
      "pass's time and of the memory per Gaussian, per pair and per pixel; --markdown, --csv and "
      "--plot (PLOT.svg time against Gaussians, PLOT_pixels.svg against image size, PLOT_memory.svg) "
      "write the report",
      &options.scaling);
  parser.add_value(
      "--tile-copies", "N",
      "with --scaling: also measure a scene of N copies of the largest SCENE side by side (2 to 64), "
      "for Gaussian counts no file has",
      [&options](const std::string& text) {
        options.tile_copies = cli::parse_int("--tile-copies", text, 2, 64);
      });

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

// Before any work: no output may overwrite an input or another output, the plot must be an SVG, and
// every output's directory must exist, so that a long run never ends in a file it cannot write.
void check_outputs(const BenchOptions& options, const std::vector<std::pair<std::string, fs::path>>& inputs) {
  if (!options.plot.empty() && !cli::has_extension(options.plot, ".svg"))
    throw cli::UsageError("--plot writes SVG: its file name must end in .svg, got '" + options.plot + "'");
  const std::vector<std::pair<std::string, fs::path>> outputs = {
      {"--csv", options.csv}, {"--json", options.json}, {"--plot", options.plot}, {"--markdown", options.markdown}};
  cli::check_distinct_paths(outputs);
  // Inputs may repeat (one cameras.json for every scene); only an output may not be one of them.
  for (const auto& input : inputs) {
    auto paths = outputs;
    paths.insert(paths.begin(), input);
    cli::check_distinct_paths(paths);
  }
  for (const auto& [flag, path] : outputs)
    if (!path.empty()) cli::check_output_path(path, flag);
}

// Every SCENE and --cameras file, which no output may overwrite.
std::vector<std::pair<std::string, fs::path>> scene_and_camera_inputs(const BenchOptions& options) {
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (const auto& scene : options.common.scenes) inputs.emplace_back("SCENE", scene);
  for (const auto& cameras : options.common.cameras_files) inputs.emplace_back("--cameras", cameras);
  return inputs;
}

// Writes the output files that were asked for (each atomically), warns about the run's validation
// messages, and returns " -> a.csv, b.json" for the closing line.
std::string write_outputs(const std::vector<std::pair<std::string, std::function<std::string()>>>& files,
                          uint64_t validation_messages) {
  std::string written;
  for (const auto& [path, make] : files) {
    if (path.empty()) continue;
    tilesplat::write_file_atomically(path, make());
    written += (written.empty() ? " -> " : ", ") + path;
  }
  if (validation_messages > 0)
    cli::print_warning(kProgram, std::to_string(validation_messages) + " Vulkan validation messages (see above)");
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
                           const std::vector<uint32_t>& order, const std::string& sort, const std::string& label) {
  std::vector<bool> seen(keys.size(), false);
  bool permutation = order.size() == keys.size();
  for (size_t i = 0; permutation && i < order.size(); ++i) {
    permutation = order[i] < keys.size() && !seen[order[i]];
    if (permutation) seen[order[i]] = true;
  }
  if (!permutation)
    throw std::runtime_error("sort strategy '" + sort + "' did not return a permutation of the keys on " + label);
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

double median_ms(const SortRow& row) { return summarize(row.ms).median; }

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
      "device,key_bits,keys,sorter,where,median_ms,min_ms,max_ms,mkeys_per_s,vs_std_sort,misordered,fallbacks,samples\n";
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
    const std::string label = row.sorter + (row.where == "cpu" ? " (cpu)" : "") + ", " +
                              std::to_string(row.key_bits) + "-bit keys";
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

// With "auto" among the sorts: which strategy it stands for on this device (its rows are labelled auto).
void print_auto_choice(const tilesplat::Renderer& renderer, const std::vector<std::string>& sorts) {
  if (std::find(sorts.begin(), sorts.end(), "auto") != sorts.end())
    std::printf("auto    sorts with %s on this device\n", renderer.sort_strategy_for("auto").c_str());
}

int run_sort_bench(const cli::ArgParser& parser, const BenchOptions& options) {
  if (!options.common.scenes.empty())
    throw cli::UsageError("--sort-bench sorts random keys and takes no SCENE");
  for (const char* flag : {"--cameras", "--view", "--views", "--orbit", "--width", "--height", "--resolutions",
                           "--azimuth", "--elevation", "--fov", "--distance", "--strict"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --sort-bench");
  check_outputs(options, {});

  std::vector<std::string> sorts = options.common.sorts;
  if (sorts.empty()) sorts = tilesplat::sort_strategies();
  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  const tilesplat::DeviceInfo device = renderer->device_info();
  std::printf("device  %s (driver %s), subgroup size %u\n", device.name.c_str(), device.driver.c_str(),
              device.subgroup_size);
  print_auto_choice(*renderer, sorts);
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
          const bool exact = tilesplat::sort_strategy_is_exact(sort);
          for (int run = 0; run < runs_per_row; ++run) {
            const auto result = renderer->sort_keys(sort, keys, uint32_t(bits));
            if (run == 0 && exact && result.order != expected) {
              progress.finish();
              throw std::runtime_error("sort strategy '" + sort + "' gave a different order than the CPU radix "
                                       "sort on " + label);
            }
            if (run == 0 && !exact) row.misordered = misordered_fraction(keys, expected, result.order, sort, label);
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

  std::printf("\n  %4s %10s  %-12s %-4s %12s %12s %12s %11s %10s\n", "bits", "keys", "sorter", "on", "median ms",
              "Mkeys/s", "vs std::sort", "misordered", "fallbacks");
  for (const auto& row : rows)
    std::printf("  %4d %10llu  %-12s %-4s %12s %12s %11sx %10s%% %10llu\n", row.key_bits,
                static_cast<unsigned long long>(row.keys), row.sorter.c_str(), row.where.c_str(),
                cli::format_fixed(median_ms(row), 3).c_str(), cli::format_fixed(mkeys_per_s(row), 2).c_str(),
                cli::format_fixed(vs_std_sort(rows, row), 2).c_str(),
                cli::format_fixed(100.0 * row.misordered, 2).c_str(), static_cast<unsigned long long>(row.fallbacks));
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

// ---------------------------------------------------------------------------------------------
// The accuracy report (accuracy_report.h): every mode against the float64 reference, per scene.

// --plot FILE.svg with several scenes: FILE_<scene>.svg for each.
fs::path scene_plot_path(const std::string& plot, const std::string& scene_file, size_t scenes) {
  if (scenes == 1) return plot;
  fs::path path(plot);
  return path.parent_path() / (path.stem().string() + "_" + fs::path(scene_file).stem().string() + ".svg");
}

// The report renders every mode against the reference itself, so a scene file's sh_degree effect is
// applied to the scene (dropping the bands it excludes gives the same images as the cap) rather than
// to the modes, whose SH cap is one of the things measured.
int run_accuracy_report(const cli::ArgParser& parser, const BenchOptions& options) {
  for (const char* flag : {"--resolutions", "--orbit", "--json"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --accuracy");
  if (options.common.sorts.size() > 1)
    throw cli::UsageError("--accuracy measures with one --sort strategy (the modes do not depend on it)");
  check_outputs(options, scene_and_camera_inputs(options));

  const std::string& command = options.command;

  // Every scene and camera first: a bad file or view fails now, not after an hour of measuring.
  struct Planned {
    BenchScene scene;
    tilesplat::accuracy::Options options;
  };
  std::vector<Planned> planned;
  const cli::ImageSize size{options.common.width, options.common.height};
  for (size_t s = 0; s < options.common.scenes.size(); ++s) {
    Planned p;
    p.scene.loaded = cli::load_scene_file(options.common.scenes[s], options.common.strict, kProgram);
    p.scene.name = p.scene.loaded.path.filename().string();
    p.scene.description = cli::describe_scene(p.scene.loaded.scene);
    p.scene.sh_degree = p.scene.loaded.scene.sh_degree;
    const auto& cameras = options.common.cameras_files;
    if (!cameras.empty()) p.scene.cameras = cameras.size() == 1 ? cameras.front() : cameras[s];
    for (const Case& c : plan_cases(options, p.scene, s, {size})) {
      p.options.views.push_back(c.camera.camera);
      p.options.view_names.push_back(c.view_label);
    }
    p.options.modes = options.common.modes;
    p.options.warmup = options.warmup;
    p.options.repeat = options.repeat;
    p.options.path = options.path;
    p.options.path_frames = options.path_frames;
    p.options.path_step = options.path_step;
    p.options.consistency_angle = options.consistency_angle;
    if (!options.common.sorts.empty()) p.options.sort = options.common.sorts.front();
    planned.push_back(std::move(p));
  }

  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  const tilesplat::DeviceInfo device = renderer->device_info();
  std::printf("device  %s (driver %s)\n", device.name.c_str(), device.driver.c_str());
  std::fflush(stdout);
  int total = 0;
  for (const auto& p : planned) total += tilesplat::accuracy::work_units(p.options, p.scene.sh_degree);
  Progress progress(total, cli::stderr_is_terminal(), "renders");
  int done_before = 0;
  std::vector<tilesplat::accuracy::SceneReport> reports;
  for (auto& p : planned) {
    auto report = tilesplat::accuracy::measure_scene(
        *renderer, p.scene.loaded.scene, p.options,
        [&](int done, int, const std::string& what) { progress.update(done_before + done, p.scene.name + ": " + what); });
    done_before += tilesplat::accuracy::work_units(p.options, p.scene.sh_degree);
    report.scene = p.scene.name;
    report.description = p.scene.description;
    std::string views;
    for (const auto& name : p.options.view_names) views += (views.empty() ? "" : ", ") + name;
    report.views = views + " at " + cli::format_size(p.options.views.front().width, p.options.views.front().height);
    p.scene.loaded.scene = {};  // measured: release its memory
    progress.finish();
    std::printf("\n%s", tilesplat::accuracy::text_table(report).c_str());
    std::fflush(stdout);
    reports.push_back(std::move(report));
  }

  std::vector<std::pair<std::string, std::function<std::string()>>> files = {
      {options.markdown, [&] { return tilesplat::accuracy::markdown(reports, device, command); }},
      {options.csv,
       [&] { return cli::with_provenance_columns(tilesplat::accuracy::csv(reports, device), command); }}};
  std::vector<std::string> plot_paths;
  if (!options.plot.empty())
    for (const auto& report : reports) {
      plot_paths.push_back(scene_plot_path(options.plot, report.scene, reports.size()).string());
      files.emplace_back(plot_paths.back(), [&report, &device] { return tilesplat::accuracy::pareto_svg(report, device); });
      if (report.consistency_angle > 0) {
        fs::path consistency = plot_paths.back();
        consistency.replace_filename(consistency.stem().string() + "_consistency.svg");
        plot_paths.push_back(consistency.string());
        files.emplace_back(plot_paths.back(),
                           [&report, &device] { return tilesplat::accuracy::consistency_svg(report, device); });
      }
    }
  const std::string written = write_outputs(files, renderer->validation_messages());
  std::fprintf(stderr, "%s: accuracy report, %d renders%s\n", kProgram, total, written.c_str());
  return cli::kExitOk;
}

int run_effects_report(const cli::ArgParser& parser, const BenchOptions& options) {
  for (const char* flag : {"--resolutions", "--json", "--plot"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --effects");
  if (options.common.scenes.size() != 1) throw cli::UsageError("--effects measures one SCENE");
  if (options.common.sorts.size() > 1) throw cli::UsageError("--effects measures with one --sort strategy");
  if (parser.seen("--antialiasing"))
    throw cli::UsageError("--antialiasing does not apply to --effects (it measures every mode)");
  check_outputs(options, {{"SCENE", options.common.scenes.front()}});
  const std::string& command = options.command;

  BenchScene scene;
  scene.loaded = cli::load_scene_file(options.common.scenes.front(), options.common.strict, kProgram);
  scene.name = scene.loaded.path.filename().string();
  scene.description = cli::describe_scene(scene.loaded.scene);
  scene.sh_degree = scene.loaded.scene.sh_degree;
  if (!options.common.cameras_files.empty()) scene.cameras = options.common.cameras_files.front();
  tilesplat::effects::Options effect_options;
  for (const Case& c : plan_cases(options, scene, 0, {{options.common.width, options.common.height}}))
    effect_options.views.push_back(c.camera.camera);
  effect_options.warmup = std::max(options.warmup, 1);  // llvmpipe compiles each variant on first use
  effect_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) effect_options.sort = options.common.sorts.front();

  tilesplat::RenderSettings base;
  if (!options.common.modes.empty()) base.accuracy = options.common.modes.front();
  cli::apply_scene_settings(scene.loaded, base);
  std::vector<tilesplat::effects::Row> rows = tilesplat::effects::plan_rows(scene.loaded.scene, base);
  std::printf("scene   %s: %s, %s\n", scene.name.c_str(), scene.description.c_str(),
              cli::format_size(effect_options.views.front().width, effect_options.views.front().height).c_str());
  std::fflush(stdout);
  tilesplat::effects::Run run;
  {
    Progress progress(tilesplat::effects::work_units(rows, effect_options), cli::stderr_is_terminal());
    run = tilesplat::effects::measure(cli::renderer_options(options.common), scene.loaded.scene, rows, effect_options,
                                      [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  std::printf("device  %s (driver %s)\n\n%s", run.device.name.c_str(), run.device.driver.c_str(),
              tilesplat::effects::text_table(rows).c_str());
  std::fflush(stdout);
  const std::string written = write_outputs(
      {{options.markdown,
        [&] { return tilesplat::effects::markdown(rows, scene.name, run.device, command); }},
       {options.csv,
        [&] {
          return cli::with_provenance_columns(tilesplat::effects::csv(rows, scene.name, run.device), command);
        }}},
      run.validation_messages);
  std::fprintf(stderr, "%s: effect costs, %zu rows%s\n", kProgram, rows.size(), written.c_str());
  return cli::kExitOk;
}

// "PLOT.svg" -> "PLOT_SUFFIX.svg": the scaling report's second and third charts.
std::string plot_with_suffix(const std::string& plot, const std::string& suffix) {
  return plot.substr(0, plot.size() - 4) + "_" + suffix + ".svg";
}

int run_scaling_report(const cli::ArgParser& parser, const BenchOptions& options) {
  for (const char* flag : {"--json", "--view", "--views", "--orbit", "--cameras", "--width", "--height"})
    if (parser.seen(flag))
      throw cli::UsageError(std::string(flag) +
                            " does not apply to --scaling (it measures each scene from the "
                            "orbit camera that frames it, at every --resolutions size)");
  if (options.common.sorts.size() > 1) throw cli::UsageError("--scaling measures with one --sort strategy");
  check_outputs(options, scene_and_camera_inputs(options));
  tilesplat::scaling::Options scaling_options;
  const std::vector<cli::ImageSize> sizes =
      options.resolutions.empty()
          ? std::vector<cli::ImageSize>{{960, 540}, {1920, 1080}, {2560, 1440}, {3840, 2160}}
          : options.resolutions;
  for (const cli::ImageSize& size : sizes) scaling_options.sizes.push_back({size.width, size.height});
  scaling_options.warmup = std::max(options.warmup, 1);  // llvmpipe compiles each variant on first use
  scaling_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) scaling_options.sort = options.common.sorts.front();

  std::vector<tilesplat::scaling::Scene> scenes;
  for (const std::string& file : options.common.scenes) {
    cli::LoadedScene loaded = cli::load_scene_file(file, options.common.strict, kProgram);
    if (loaded.scene.empty()) throw cli::UsageError("'" + file + "' has no Gaussians to measure");
    std::printf("scene   %s: %s\n", loaded.path.filename().string().c_str(),
                cli::describe_scene(loaded.scene).c_str());
    scenes.push_back({loaded.path.filename().string(), std::move(loaded.scene)});
  }
  if (options.tile_copies > 0) {
    const auto largest = std::max_element(scenes.begin(), scenes.end(), [](const auto& a, const auto& b) {
      return a.scene.size() < b.scene.size();
    });
    tilesplat::scaling::Scene tiled{largest->name + " x" + std::to_string(options.tile_copies) + " (tiled)",
                                    tilesplat::scaling::tile_scene(largest->scene, options.tile_copies)};
    std::printf("scene   %s: %s\n", tiled.name.c_str(), cli::describe_scene(tiled.scene).c_str());
    scenes.push_back(std::move(tiled));
  }
  std::fflush(stdout);
  tilesplat::scaling::Run run;
  {
    Progress progress(tilesplat::scaling::work_units(scenes, scaling_options), cli::stderr_is_terminal());
    run = tilesplat::scaling::measure(
        cli::renderer_options(options.common), scenes, scaling_options,
        [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  const std::vector<tilesplat::scaling::Fit> fits = tilesplat::scaling::fit(run.points);
  std::printf("device  %s (driver %s)\n\n%s", run.device.name.c_str(), run.device.driver.c_str(),
              tilesplat::scaling::text_report(run, fits).c_str());
  std::fflush(stdout);
  std::vector<std::pair<std::string, std::function<std::string()>>> files = {
      {options.markdown, [&] { return tilesplat::scaling::markdown(run, fits, options.command); }},
      {options.csv,
       [&] { return cli::with_provenance_columns(tilesplat::scaling::csv(run), options.command); }},
      {options.plot, [&] { return tilesplat::scaling::svg_time_vs_gaussians(run); }}};
  if (!options.plot.empty()) {
    files.push_back({plot_with_suffix(options.plot, "pixels"),
                     [&] { return tilesplat::scaling::svg_time_vs_pixels(run); }});
    files.push_back(
        {plot_with_suffix(options.plot, "memory"), [&] { return tilesplat::scaling::svg_memory(run); }});
  }
  const std::string written = write_outputs(files, run.validation_messages);
  std::fprintf(stderr, "%s: scaling, %zu scenes x %zu sizes%s\n", kProgram, scenes.size(),
               scaling_options.sizes.size(), written.c_str());
  return cli::kExitOk;
}

// The views the format report compares images at: those asked for, else two that see the scene
// from different sides (the first and the middle view of its cameras, or two opposite orbit views).
std::vector<Case> plan_format_views(const cli::ArgParser& parser, BenchOptions options, const BenchScene& reference) {
  const bool chosen = parser.seen("--view") || parser.seen("--views") || parser.seen("--orbit");
  if (!chosen) {
    const cli::SceneViews own = cli::scene_views(reference.loaded);
    const size_t count = !reference.cameras.empty() ? cli::load_camera_views(reference.cameras).size() : own.views.size();
    if (count > 0) {
      options.views = {0};
      if (count > 1) options.views.push_back(int(count / 2));
    } else {
      options.orbit = 2;
    }
  }
  return plan_cases(options, reference, 0, {{options.common.width, options.common.height}});
}

int run_formats_report(const cli::ArgParser& parser, const BenchOptions& options) {
  for (const char* flag : {"--resolutions", "--json"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --formats");
  if (options.common.scenes.size() < 2)
    throw cli::UsageError("--formats compares files with a reference: give the lossless PLY first, then one or more "
                          "files of the same scene");
  if (options.common.sorts.size() > 1) throw cli::UsageError("--formats renders with one --sort strategy");
  if (options.common.cameras_files.size() > 1) throw cli::UsageError("--formats takes one --cameras for all its files");
  check_outputs(options, scene_and_camera_inputs(options));
  const std::string& command = options.command;

  BenchScene reference;
  reference.loaded = cli::load_scene_file(options.common.scenes.front(), options.common.strict, kProgram);
  if (!options.common.cameras_files.empty()) reference.cameras = options.common.cameras_files.front();
  tilesplat::formats::Options format_options;
  std::string view_names;
  for (const Case& c : plan_format_views(parser, options, reference)) {
    format_options.views.push_back(c.camera.camera);
    format_options.view_names.push_back(c.view_label);
    view_names += (view_names.empty() ? "" : ", ") + c.view_label;
  }
  reference.loaded.scene = {};  // measure() loads every file itself, the reference included
  format_options.warmup = options.warmup;
  format_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) format_options.settings.sort = options.common.sorts.front();
  if (!options.common.modes.empty()) format_options.settings.accuracy = options.common.modes.front();
  if (options.common.antialiasing) format_options.settings.antialiasing = *options.common.antialiasing;

  const std::vector<fs::path> files(options.common.scenes.begin() + 1, options.common.scenes.end());
  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  tilesplat::formats::Report report;
  {
    const int total = tilesplat::formats::work_units(files.size(), format_options);
    Progress progress(total, cli::stderr_is_terminal(), "steps");
    report = tilesplat::formats::measure(*renderer, options.common.scenes.front(), files, format_options,
                                         [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  report.views_label = view_names + " at " + cli::format_size(format_options.views.front().width,
                                                              format_options.views.front().height);
  std::printf("device  %s (driver %s)\n\n%s", report.device.name.c_str(), report.device.driver.c_str(),
              tilesplat::formats::text_table(report).c_str());
  std::fflush(stdout);
  const std::string written = write_outputs(
      {{options.markdown, [&] { return tilesplat::formats::markdown(report, command); }},
       {options.csv, [&] { return cli::with_provenance_columns(tilesplat::formats::csv(report), command); }},
       {options.plot, [&] { return tilesplat::formats::size_psnr_svg(report); }}},
      report.validation_messages);
  std::fprintf(stderr, "%s: format costs, %zu files against %s%s\n", kProgram, files.size(),
               report.reference_name.c_str(), written.c_str());
  return cli::kExitOk;
}

// ---------------------------------------------------------------------------------------------
// The frame benchmark

// What the parser cannot check flag by flag. Throws UsageError.
void check_frame_options(const cli::ArgParser& parser, const BenchOptions& options) {
  for (const char* flag : {"--sort-sizes", "--key-bits"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " applies only with --sort-bench");
  if (int(options.accuracy) + int(options.effects) + int(options.formats) + int(options.scaling) > 1)
    throw cli::UsageError("--accuracy, --effects, --formats and --scaling are separate runs");
  if (parser.seen("--tile-copies") && !options.scaling)
    throw cli::UsageError("--tile-copies applies only with --scaling");
  if (!options.accuracy) {
    if (parser.seen("--path-frames")) throw cli::UsageError("--path-frames applies only with --accuracy");
    if (parser.seen("--markdown") && !options.effects && !options.formats && !options.scaling)
      throw cli::UsageError("--markdown applies only with --accuracy, --effects, --formats or --scaling");
    if (options.common.modes.size() > 1)
      throw cli::UsageError("several --mode combinations are compared by --accuracy; the frame benchmark takes one");
  }
  cli::check_common_options(parser, options.common);
  const size_t cameras = options.common.cameras_files.size();
  const size_t scenes = options.common.scenes.size();
  if (cameras > 1 && cameras != scenes)
    throw cli::UsageError("--cameras was given " + std::to_string(cameras) + " times for " +
                          std::to_string(scenes) + " scenes: give it once for every scene, or once per scene in "
                          "the order of the scenes");
  if (parser.seen("--views")) {
    if (cameras == 0 && !cli::any_scene_file(options.common))
      throw cli::UsageError("--views needs --cameras FILE.json (without it the cameras orbit the scene: see --orbit)");
    if (parser.seen("--view")) throw cli::UsageError("--view and --views cannot be combined");
  }
  if (parser.seen("--orbit") && cameras > 0)
    throw cli::UsageError("--orbit applies only to the orbit camera and cannot be combined with --cameras");
  if (parser.seen("--resolutions"))
    for (const char* flag : {"--width", "--height"})
      if (parser.seen(flag))
        throw cli::UsageError(std::string("--resolutions and ") + flag +
                              " cannot be combined: give every size in --resolutions");
}

int run(int argc, char** argv) {
  cli::load_sort_plugins(argc, argv);  // before the parser lists and checks the sort names
  BenchOptions options;
  cli::ArgParser parser(kProgram, "tilesplat-bench SCENE.ply|SCENE.json [SCENE...] [options]",
                        "Renders 3D Gaussian Splatting scenes repeatedly and prints the GPU time of every pass "
                        "(median, min, max over the measured frames) for each sort strategy, with the frame's "
                        "CPU time, visible Gaussians, intersections and device memory. Every scene is measured "
                        "at every size (--resolutions) from every camera of its path (--views of --cameras, or "
                        "--orbit); a progress bar on stderr counts the frames of the whole run.");
  add_bench_options(parser, options);
  if (cli::parse_and_handle_info_flags(parser, argc, argv, options.common)) return cli::kExitOk;
  options.command = cli::command_line(kProgram, argc, argv);
  if (options.sort_bench) return run_sort_bench(parser, options);
  check_frame_options(parser, options);
  if (options.accuracy) return run_accuracy_report(parser, options);
  if (options.effects) return run_effects_report(parser, options);
  if (options.formats) return run_formats_report(parser, options);
  if (options.scaling) return run_scaling_report(parser, options);
  check_outputs(options, scene_and_camera_inputs(options));

  std::vector<std::string> sorts = options.common.sorts;
  if (sorts.empty()) sorts = tilesplat::sort_strategies();
  if (sorts.empty()) sorts = {tilesplat::RenderSettings{}.sort};
  std::vector<cli::ImageSize> sizes = options.resolutions;
  if (sizes.empty()) sizes = {{options.common.width, options.common.height}};

  // Every scene and camera first: a bad file or view fails now, not after an hour of measuring.
  std::vector<BenchScene> scenes;
  std::vector<Case> cases;
  for (size_t s = 0; s < options.common.scenes.size(); ++s) {
    BenchScene scene;
    scene.loaded = cli::load_scene_file(options.common.scenes[s], options.common.strict, kProgram);
    scene.name = scene.loaded.path.filename().string();
    scene.description = cli::describe_scene(scene.loaded.scene);
    scene.gaussians = scene.loaded.scene.size();
    scene.sh_degree = scene.loaded.scene.sh_degree;
    const auto& cameras = options.common.cameras_files;
    if (!cameras.empty()) scene.cameras = cameras.size() == 1 ? cameras.front() : cameras[s];
    auto scene_cases = plan_cases(options, scene, s, sizes);
    cases.insert(cases.end(), std::make_move_iterator(scene_cases.begin()),
                 std::make_move_iterator(scene_cases.end()));
    scenes.push_back(std::move(scene));
  }

  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  const tilesplat::DeviceInfo device = renderer->device_info();
  for (const auto& scene : scenes)
    std::printf("scene   %s: %s, loaded in %s ms\n", scene.name.c_str(), scene.description.c_str(),
                cli::format_fixed(scene.loaded.load_ms, 1).c_str());
  std::printf("device  %s (driver %s), subgroup size %u\n", device.name.c_str(), device.driver.c_str(),
              device.subgroup_size);
  const int frames_per_row = options.warmup + options.repeat;
  const int rows = static_cast<int>(cases.size() * sorts.size());
  const int total_frames = frames_per_row * rows;
  print_auto_choice(*renderer, sorts);
  std::printf("frames  %d warm-up + %d measured per camera and sort; %zu cameras x %zu sorts, %d frames\n",
              options.warmup, options.repeat, cases.size(), sorts.size(), total_frames);
  std::fflush(stdout);

  const auto start = std::chrono::steady_clock::now();
  {
    Progress progress(total_frames, cli::stderr_is_terminal());
    int done = 0;
    std::vector<tilesplat::RenderImage> images;  // per strategy, of the current camera
    for (size_t i = 0; i < cases.size(); ++i) {
      Case& c = cases[i];
      BenchScene& scene = scenes[c.scene];
      // One renderer for the whole run: set_scene replaces the scene, once per scene.
      if (i == 0 || cases[i - 1].scene != c.scene) renderer->set_scene(scene.loaded.scene);
      const std::string where = scene.name + " " + size_of(c) + " " + c.view_label + " ";
      for (const auto& sort : sorts) {
        tilesplat::RenderSettings settings;
        settings.sort = sort;
        settings.reuse_lists = false;  // every measured frame is a whole frame, not a composite on reused lists
        if (!options.common.modes.empty()) settings.accuracy = options.common.modes.front();
        cli::apply_scene_settings(scene.loaded, settings);
        if (options.common.antialiasing) settings.antialiasing = *options.common.antialiasing;
        Collector collector(sort);
        for (int frame = 0; frame < frames_per_row; ++frame) {
          // Rendering reads the image back, which is part of cpu frame; the first measured image of
          // each strategy is kept to check that the strategies agree.
          tilesplat::RenderImage image = renderer->render(c.camera.camera, settings);
          if (frame == options.warmup) images.push_back(std::move(image));
          if (frame >= options.warmup) collector.add(renderer->last_frame_stats());
          progress.update(++done, where + sort);
        }
        c.results.push_back(collector.take());
      }
      record_image_agreement(c.results, images);
      images.clear();
      // The renderer holds its own copy; the next scene need not share memory with this one.
      if (i + 1 == cases.size() || cases[i + 1].scene != c.scene) scene.loaded.scene = {};
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::vector<Group> groups = group_cases(cases, sorts.size());
  for (const auto& group : groups) print_group(group, scenes[group.cases.front()->scene], options);
  std::fflush(stdout);

  const std::string written = write_outputs(
      {{options.csv,
        [&] { return cli::with_provenance_columns(make_csv(groups, scenes, device), options.command); }},
       {options.json, [&] { return make_json(groups, scenes, device, options); }},
       {options.plot, [&] { return make_frame_svg(groups, scenes, device, options); }}},
      renderer->validation_messages());
  std::string what = scenes.size() == 1 ? scenes.front().name + ", " + scenes.front().description
                                        : std::to_string(scenes.size()) + " scenes";
  what += cases.size() == 1 ? ", " + size_of(cases.front()) : ", " + std::to_string(cases.size()) + " cameras";
  std::fprintf(stderr, "%s: %s, %d frames in %s s%s\n", kProgram, what.c_str(), total_frames,
               cli::format_fixed(seconds, 2).c_str(), written.c_str());
  return cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
