// What the bench measures, as rows of samples (a Series per metric), how they are summarized (median,
// min, max), and the helpers every output format of the bench shares (CSV numbers, JSON values).
#pragma once

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "tilesplat/image.h"
#include "tilesplat/renderer.h"

namespace tilesplat::bench {

enum class Unit {
  kMilliseconds,
  kCount,
  kMebibytes,
  kDecibels,
  kColour
};  // kColour: a difference, 1 = white

const char* unit_name(Unit unit);
int unit_decimals(Unit unit);
// The value with the unit's decimals.
std::string format_value(double value, Unit unit);

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

Summary summarize(std::vector<double> samples);

struct StrategyResult {
  std::string sort;
  std::vector<Series> passes;  // in frame order (of first appearance)
  std::vector<Series> frame;   // gpu frame, cpu frame, counts, memory
};

Series& find_series(std::vector<Series>& rows, const std::string& name, const std::string& kind, Unit unit);
const Series* find_series(const std::vector<Series>& rows, const std::string& name);
// The median of the named row; 0 when there is none.
double median_of(const std::vector<Series>& rows, const std::string& name);

// Every exact strategy must give the same image to the bit; a quantizing one (cpu-radix16) may
// not, and what that costs in accuracy is reported next to its time: the largest RGB difference
// from the first exact strategy's image (0 when identical) and, when they differ, the PSNR.
constexpr const char* kImageMaxAbs = "image max abs vs exact";
constexpr const char* kImagePsnr = "image psnr vs exact";

void record_image_agreement(std::vector<StrategyResult>& results, const std::vector<RenderImage>& images);

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
    if (stats.scene_parts > 1) {  // a scene rendered in depth-ordered parts (--memory-budget)
      add_frame("scene parts", Unit::kCount, double(stats.scene_parts));
      add_frame("peak device memory", Unit::kMebibytes, double(stats.peak_device_bytes) / (1024.0 * 1024.0));
      add_frame("depth order", Unit::kMilliseconds, stats.depth_order_ms);  // host time, before the parts
    }
  }

  StrategyResult take() { return std::move(result_); }

 private:
  void add_frame(const char* name, Unit unit, double value) {
    find_series(result_.frame, name, "frame", unit).samples.push_back(value);
  }

  StrategyResult result_;
};

// A CSV number: exact for counts (integers up to 2^53), 9 significant digits otherwise; "null" when
// not finite, as the JSON says.
std::string number_text(double value);

// JSON outputs are built as nlohmann::ordered_json (members in the order written here) and dumped
// once; a value that is not finite becomes null.
using Json = nlohmann::ordered_json;

// A JSON number: a count stays an integer, anything else a double (null when not finite).
Json json_number(double value);
// The "tilesplat" build and "command" members that every JSON output starts with.
void add_provenance(Json& json, const std::string& tool, const std::string& command);
Json json_device(const DeviceInfo& device);
// "NAME, DRIVER", for the charts' subtitles.
std::string device_line(const DeviceInfo& device);

// Calls visit(row) for every metric of a result, passes first.
template <typename Visit>
void for_each_metric(const StrategyResult& result, Visit&& visit) {
  for (const auto* rows : {&result.passes, &result.frame})
    for (const auto& row : *rows) visit(row);
}

template <typename T>
void add_unique(std::vector<T>& items, const T& item) {
  if (std::find(items.begin(), items.end(), item) == items.end()) items.push_back(item);
}

// "a, b, c".
std::string join(const std::vector<std::string>& items);

}  // namespace tilesplat::bench
