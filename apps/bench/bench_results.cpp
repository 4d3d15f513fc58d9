#include "bench_results.h"

#include <cmath>
#include <cstdio>

#include "cli.h"
#include "tilesplat/sort_strategy.h"
#include "tilesplat/version.h"

namespace tilesplat::bench {

namespace cli = tilesplat::cli;

const char* unit_name(Unit unit) {
  switch (unit) {
    case Unit::kMilliseconds:
      return "ms";
    case Unit::kCount:
      return "";
    case Unit::kMebibytes:
      return "MiB";
    case Unit::kDecibels:
      return "dB";
    case Unit::kColour:
      return "";
  }
  return "";
}

int unit_decimals(Unit unit) {
  switch (unit) {
    case Unit::kMilliseconds:
      return 3;
    case Unit::kCount:
      return 0;
    case Unit::kMebibytes:
      return 2;
    case Unit::kDecibels:
      return 2;
    case Unit::kColour:
      return 6;
  }
  return 3;
}

Summary summarize(std::vector<double> samples) {
  Summary summary;
  if (samples.empty()) return summary;
  summary.min = *std::min_element(samples.begin(), samples.end());
  summary.max = *std::max_element(samples.begin(), samples.end());
  summary.median = cli::median(std::move(samples));
  return summary;
}

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

void record_image_agreement(std::vector<StrategyResult>& results,
                            const std::vector<tilesplat::RenderImage>& images) {
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
      std::fprintf(stderr,
                   "warning: exact sort strategies '%s' and '%s' gave different images (max abs %g)\n",
                   results[i].sort.c_str(), results[reference].sort.c_str(), diff.max_abs);
  }
}

std::string format_value(double value, Unit unit) {
  return cli::format_fixed(value, unit_decimals(unit));
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

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

std::string device_line(const tilesplat::DeviceInfo& device) {
  return device.name + ", " + device.driver;
}

}  // namespace tilesplat::bench
