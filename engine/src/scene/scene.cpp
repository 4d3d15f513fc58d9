// Scene-level entry points: the format chosen by content, load reports and robust scene bounds.
#include "tilesplat/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "scene/scene_readers.h"
#include "scene/scene_reading.h"
#include "tilesplat/lod_set.h"

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

namespace {

// A LOD set's finest level, the whole capture (tilesplat/lod_set.h picks other levels).
GaussianScene read_lod_set_level0(std::string_view text, const std::filesystem::path& path,
                                  const LoadOptions& options, LoadReport* report) {
  const LodSet set = LodSet::parse(text, path);
  GaussianScene scene = set.load_level(0, options);
  if (report) {
    *report = LoadReport{.format = "lod set (level 0 of " + std::to_string(set.levels()) + ")",
                         .version = "1",
                         .gaussians_in_file = scene.size()};
  }
  return scene;
}

// `file`: where `data` came from when it is a file on disk (its path, and its contents, which a reader may
// let go of as it decodes them); nullptr for bytes in memory.
struct OpenFile {
  const std::filesystem::path& path;
  detail::FileContents& contents;
};

GaussianScene read_any(std::span<const std::byte> data, const std::string& name, const OpenFile* file,
                       const LoadOptions& options, LoadReport* report) {
  const std::filesystem::path* path = file ? &file->path : nullptr;
  const detail::FileLoader no_files;
  const detail::FileLoader files = path ? detail::sibling_loader(*path) : no_files;
  switch (detail::container_of(data)) {
    case detail::Container::kPly:
      return file ? detail::read_ply_file(file->contents, name, options, report)
                  : parse_ply(data, name, options, report);
    case detail::Container::kSpz:
      return detail::read_spz(data, name, options, report, file ? &file->contents : nullptr);
    case detail::Container::kZip:
      return detail::read_sog_zip(data, name, options, report);
    case detail::Container::kGlb:
      return detail::read_gltf(data, name, files, options, report);
    case detail::Container::kKsplat:
      return detail::read_ksplat(data, name, options, report);
    case detail::Container::kRad:
      return detail::read_rad(data, name, files, options, report);
    case detail::Container::kJson: {
      const std::string_view text(reinterpret_cast<const char*>(data.data()), data.size());
      if (detail::is_lod_index(text)) {
        if (!path) detail::fail(name, "a LOD set index: its chunks are files, read it with load_scene");
        return read_lod_set_level0(text, *path, options, report);
      }
      if (detail::is_sog_meta(text)) {
        if (!path) detail::fail(name, "an unbundled SOG meta.json: its images are files, read it with load_scene");
        return detail::read_sog_meta(text, name, files, options, report);
      }
      return detail::read_gltf(data, name, files, options, report);
    }
    case detail::Container::kUnknown:
      break;
  }
  const std::string extension = lowercase(std::filesystem::path(name).extension().string());
  if (extension == ".splat") return detail::read_splat(data, name, options, report);
  if (extension == ".ksplat") return detail::read_ksplat(data, name, options, report);  // its error says why
  if (data.empty()) detail::fail(name, "empty file, not a scene file");
  detail::fail(name, "unrecognized scene format: not a PLY, compressed PLY, SPZ, SOG, glTF, GLB, ksplat or RAD file "
                     "by its content (supported: .ply, .compressed.ply, .splat, .spz, .sog, SOG meta.json, .glb, "
                     ".gltf, .ksplat, .rad; "
                     "a headerless .splat file needs the .splat extension)");
}

}  // namespace

GaussianScene load_scene(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report) {
  detail::FileContents contents;
  detail::open_scene_file(path, contents);
  const OpenFile file{path, contents};
  return read_any(contents.bytes(), path.string(), &file, options, report);
}

GaussianScene parse_scene(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                          LoadReport* report) {
  return read_any(data, std::string(name), nullptr, options, report);
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
  if (scene.positions.size() < 3 * scene.size()) return {};
  return detail::bounds_of_positions(std::span(scene.positions).first(3 * scene.size()));
}

namespace detail {

Bounds bounds_of_positions(std::span<const float> positions) {
  Bounds bounds;
  const size_t count = positions.size() / 3;
  if (count == 0) return bounds;

  std::vector<double> axis(count);
  for (size_t a = 0; a < 3; ++a) {
    double low = positions[a];
    double high = low;
    for (size_t i = 0; i < count; ++i) {
      const double value = positions[3 * i + a];
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
    const double dx = positions[3 * i] - bounds.center[0];
    const double dy = positions[3 * i + 1] - bounds.center[1];
    const double dz = positions[3 * i + 2] - bounds.center[2];
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

}  // namespace detail

SceneStatistics compute_statistics(const GaussianScene& scene) {
  SceneStatistics stats;
  const size_t count = scene.size();
  if (count == 0) return stats;
  std::vector<double> axis(count);
  // Nearest-rank percentiles.
  const auto rank = [count](double p) {
    const size_t r = static_cast<size_t>(std::ceil(p * static_cast<double>(count)));
    return std::min(count - 1, r > 0 ? r - 1 : 0);
  };
  for (size_t a = 0; a < 3; ++a) {
    for (size_t i = 0; i < count; ++i) axis[i] = scene.positions[3 * i + a];
    const auto [low, high] = std::minmax_element(axis.begin(), axis.end());
    stats.min[a] = *low;
    stats.max[a] = *high;
    std::nth_element(axis.begin(), axis.begin() + static_cast<std::ptrdiff_t>(rank(0.01)), axis.end());
    stats.robust_min[a] = axis[rank(0.01)];
    std::nth_element(axis.begin(), axis.begin() + static_cast<std::ptrdiff_t>(rank(0.99)), axis.end());
    stats.robust_max[a] = axis[rank(0.99)];
  }
  const auto [low_logit, high_logit] = std::minmax_element(scene.opacity_logits.begin(), scene.opacity_logits.end());
  stats.opacity_min = 1.0 / (1.0 + std::exp(-static_cast<double>(*low_logit)));
  stats.opacity_max = 1.0 / (1.0 + std::exp(-static_cast<double>(*high_logit)));
  const auto [low_scale, high_scale] = std::minmax_element(scene.log_scales.begin(), scene.log_scales.end());
  stats.scale_min = std::exp(static_cast<double>(*low_scale));
  stats.scale_max = std::exp(static_cast<double>(*high_scale));
  return stats;
}

}  // namespace tilesplat
