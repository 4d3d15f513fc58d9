// Scene-level entry points: format dispatch, load reports and robust scene bounds.
#include "tilesplat/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <vector>

namespace tilesplat {
namespace {

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// Median of a copy; the mean of the two middle values for an even count.
double median(std::vector<double> values) {
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle), values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  const double lower =
      *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle));
  return 0.5 * (lower + upper);
}

}  // namespace

GaussianScene load_scene(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report) {
  const std::string extension = lowercase(path.extension().string());
  if (extension == ".ply") return load_ply(path, options, report);
  std::string message = path.string();
  message += ": unsupported scene format ";
  if (extension.empty()) {
    message += "(no extension)";
  } else {
    message += '\'';
    message += path.extension().string();
    message += '\'';
  }
  message += " (supported: .ply)";
  throw SceneError(message);
}

std::string LoadReport::summary() const {
  if (dropped == 0) return {};
  std::string line = "dropped " + std::to_string(dropped) + " of " + std::to_string(gaussians_in_file) +
                     " Gaussians with non-finite values";
  if (!dropped_by_property.empty()) {
    line += " (";
    for (size_t i = 0; i < dropped_by_property.size(); ++i) {
      const DroppedProperty& entry = dropped_by_property[i];
      if (i > 0) line += "; ";
      line += entry.property + ": " + std::to_string(entry.count) + ", first at " +
              std::to_string(entry.first_index);
    }
    line += ")";
  }
  return line;
}

Bounds compute_bounds(const GaussianScene& scene) {
  Bounds bounds;
  const size_t count = scene.size();
  if (count == 0 || scene.positions.size() < 3 * count) return bounds;

  std::vector<double> axis(count);
  for (size_t a = 0; a < 3; ++a) {
    double low = scene.positions[a];
    double high = low;
    for (size_t i = 0; i < count; ++i) {
      const double value = scene.positions[3 * i + a];
      axis[i] = value;
      low = std::min(low, value);
      high = std::max(high, value);
    }
    bounds.min[a] = low;
    bounds.max[a] = high;
    // The median, not the mean or the box centre: a few far floaters must not move the centre.
    bounds.center[a] = median(axis);
  }

  std::vector<double> distances(count);
  for (size_t i = 0; i < count; ++i) {
    const double dx = scene.positions[3 * i] - bounds.center[0];
    const double dy = scene.positions[3 * i + 1] - bounds.center[1];
    const double dz = scene.positions[3 * i + 2] - bounds.center[2];
    distances[i] = std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  // Nearest-rank 95th percentile: covers most Gaussians while ignoring the outlying 5%.
  const size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(count)));
  const size_t index = std::min(count - 1, rank > 0 ? rank - 1 : 0);
  std::nth_element(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(index),
                   distances.end());
  bounds.radius = distances[index];
  return bounds;
}

}  // namespace tilesplat
