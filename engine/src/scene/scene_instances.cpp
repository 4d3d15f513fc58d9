// A scene description's models as scenes: each file loaded once and placed as instances
// (SceneInstances), merged into one scene (load_described_scene), or only their bounds.
#include <algorithm>
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene_merge.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;

// The models' load reports as one: counts summed, properties named with their file.
void add_report(LoadReport& total, const LoadReport& part, const fs::path& file) {
  total.gaussians_in_file += part.gaussians_in_file;
  total.dropped += part.dropped;
  for (DroppedProperty dropped : part.dropped_by_property) {
    dropped.property = file.filename().string() + " " + dropped.property;
    total.dropped_by_property.push_back(std::move(dropped));
  }
  for (const auto& property : part.ignored_properties)
    if (std::find(total.ignored_properties.begin(), total.ignored_properties.end(), property) ==
        total.ignored_properties.end())
      total.ignored_properties.push_back(property);
  if (total.format.find(part.format) == std::string::npos)
    total.format += (total.format.back() == '(' ? "" : ", ") + part.format;
}

}  // namespace

ModelTransform SceneInstances::Instance::at(double t) const {
  return end_transform ? transform_between(transform, *end_transform, t) : transform;
}

bool SceneInstances::moves() const {
  return std::any_of(instances.begin(), instances.end(),
                     [](const Instance& instance) { return instance.end_transform.has_value(); });
}

size_t SceneInstances::size() const {
  size_t total = 0;
  for (const Instance& instance : instances) total += files.at(instance.file).size();
  return total;
}

SceneInstances load_scene_instances(const SceneDescription& description, const LoadOptions& options,
                                    LoadReport* report) {
  LoadReport total;
  total.format = "scene description (";
  SceneInstances out;
  std::map<fs::path, size_t> file_index;  // each file once, however many models name it
  std::vector<LoadReport> file_reports;
  for (size_t i = 0; i < description.models.size(); ++i) {
    const SceneModel& model = description.models[i];
    const std::string where = description.file.string() + ": models[" + std::to_string(i) + "]: ";
    auto found = file_index.find(model.path);
    if (found == file_index.end()) {
      LoadReport part;
      try {
        out.files.push_back(load_scene(model.path, options, &part));
      } catch (const SceneError& error) {
        throw SceneError(where + error.what());
      } catch (const std::invalid_argument& error) {
        throw SceneError(where + model.path.string() + ": " + error.what());
      }
      file_reports.push_back(std::move(part));
      found = file_index.emplace(model.path, out.files.size() - 1).first;
    }
    try {
      validate(model.transform);
      if (model.motion) transform_between(model.transform, *model.motion, 1);  // validates the end
    } catch (const std::invalid_argument& error) {
      throw SceneError(where + model.path.string() + ": transform_scene: " + error.what());
    }
    out.instances.push_back({found->second, model.transform, model.motion});
    add_report(total, file_reports[found->second], model.path);
    const GaussianScene& file = out.files[found->second];
    out.sh_degree = std::max(out.sh_degree, file.sh_degree);
    out.normals = out.normals || file.has_normals();
  }
  total.format += ")";
  // Bands the sh_degree effect never evaluates are not kept (nor uploaded, nor allocated on a device).
  if (description.effects.sh_degree) out.sh_degree = std::min(out.sh_degree, *description.effects.sh_degree);
  if (report) *report = std::move(total);
  return out;
}

GaussianScene merge_instances(const SceneInstances& scene) {
  return merge_instances(scene, 0);
}

GaussianScene merge_instances(const SceneInstances& scene, double t) {
  // One transformed copy at a time into the merged scene: at most one copy exists besides the files and
  // the result.
  GaussianScene merged;
  detail::reserve_merged(merged, scene.size(), scene.sh_degree, scene.normals);
  for (const SceneInstances::Instance& instance : scene.instances)
    detail::append_merged(merged, transform_scene(scene.files.at(instance.file), instance.at(t)),
                          scene.normals);
  return merged;
}

Bounds compute_bounds(const SceneInstances& scene) {
  GaussianScene positions;  // the placed positions alone, which is all compute_bounds reads
  positions.positions.reserve(3 * scene.size());
  for (const SceneInstances::Instance& instance : scene.instances) {
    const GaussianScene& file = scene.files.at(instance.file);
    const detail::PositionPlacement placement(instance.transform);
    for (size_t i = 0; i < file.size(); ++i) {
      const std::array<float, 3> p = placement.place(&file.positions[3 * i], i);
      positions.positions.insert(positions.positions.end(), p.begin(), p.end());
    }
  }
  positions.opacity_logits.assign(positions.positions.size() / 3, 0.0f);
  return compute_bounds(positions);
}

GaussianScene load_described_scene(const SceneDescription& description, const LoadOptions& options,
                                   LoadReport* report) {
  const SceneInstances instances = load_scene_instances(description, options, report);
  // merge_instances, naming the model whose placement fails.
  GaussianScene merged;
  detail::reserve_merged(merged, instances.size(), instances.sh_degree, instances.normals);
  for (size_t i = 0; i < instances.instances.size(); ++i) {
    const SceneInstances::Instance& instance = instances.instances[i];
    try {
      detail::append_merged(merged, transform_scene(instances.files[instance.file], instance.transform),
                            instances.normals);
    } catch (const std::invalid_argument& error) {
      throw SceneError(description.file.string() + ": models[" + std::to_string(i) +
                       "]: " + description.models[i].path.string() + ": " + error.what());
    }
  }
  return merged;
}

}  // namespace tilesplat
