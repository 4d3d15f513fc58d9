#include "scene_loading.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <new>
#include <system_error>

#include "app_run.h"
#include "output_paths.h"
#include "text.h"
#include "tilesplat/camera_sets.h"

namespace tilesplat::cli {

namespace fs = std::filesystem;

namespace {

// An error message that names `path`: library messages normally do; this makes sure.
std::string naming_file(const fs::path& path, std::string_view message) {
  const std::string text = one_line(message);
  if (text.find(path.filename().string()) != std::string::npos) return text;
  return path.string() + ": " + text;
}

void require_input_file(const fs::path& path, std::string_view what) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status))
    throw std::runtime_error("cannot read " + std::string(what) + " " + single_quoted(path.string()) +
                             ": no such file");
  if (fs::is_directory(status))
    throw std::runtime_error("cannot read " + std::string(what) + " " + single_quoted(path.string()) +
                             ": it is a directory");
}

void check_camera_size(const Camera& camera) {
  if (camera.width < 1 || camera.height < 1 || camera.width > kMaxImageSide || camera.height > kMaxImageSide)
    throw UsageError("the image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                     " is out of range (1 to " + std::to_string(kMaxImageSide) + " pixels a side)");
}

double elapsed_ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

size_t LoadedScene::gaussians() const {
  if (instances) return instances->size();
  if (in_parts) return in_parts->size();
  if (lod && lod->splat_budget > 0) return lod->set->level_size(0);
  if (lod_tree && lod_tree->splat_budget > 0) return lod_tree->tree->level_nodes(0).size();
  return scene.size();
}

Bounds LoadedScene::bounds() const {
  if (lod) return lod->framing;
  if (lod_tree) return lod_tree->framing;
  if (in_parts) return in_parts->bounds();
  return instances ? compute_bounds(*instances) : compute_bounds(scene);
}

namespace {

// The set's level, or nothing under a splat budget (each frame gathers its own), and its framing.
void load_lod_set(LoadedScene& loaded, const LodOptions& options, const LoadOptions& load_options) {
  auto set = std::make_shared<LodSet>(LodSet::open(loaded.path));
  LoadedLodSet lod;
  lod.level = options.level.value_or(0);
  lod.splat_budget = options.splat_budget;
  set->level_size(lod.level);  // a level the set does not have is an error before anything is read
  if (lod.splat_budget == 0) loaded.scene = set->load_level(lod.level, load_options);
  const int coarsest = set->levels() - 1;
  lod.framing = compute_bounds(lod.splat_budget == 0 && lod.level == coarsest
                                   ? loaded.scene
                                   : set->load_level(coarsest, load_options));
  loaded.report = LoadReport{.format = "lod set", .version = "1", .gaussians_in_file = set->level_size(0)};
  lod.set = std::move(set);
  loaded.lod = std::move(lod);
}

// The tree's level, or nothing under a splat budget (each frame cuts its own), and its framing.
void load_lod_tree(LoadedScene& loaded, const LodOptions& options, const LoadOptions& load_options) {
  auto tree = std::make_shared<SplatLodTree>(SplatLodTree::open(loaded.path));
  LoadedLodTree lod;
  lod.level = options.level.value_or(0);
  lod.splat_budget = options.splat_budget;
  if (lod.level >= tree->levels())
    throw UsageError("--lod " + std::to_string(lod.level) + ": " + single_quoted(loaded.path.string()) + " has " +
                     std::to_string(tree->levels()) + " levels (0 to " + std::to_string(tree->levels() - 1) + ")");
  const GaussianScene leaves = tree->load_level(0, load_options);
  lod.framing = compute_bounds(leaves);
  if (lod.splat_budget == 0) loaded.scene = lod.level == 0 ? leaves : tree->load_level(lod.level, load_options);
  loaded.report = LoadReport{.format = "rad LOD tree (" + std::to_string(tree->levels()) + " levels)",
                             .version = "1",
                             .gaussians_in_file = tree->nodes()};
  lod.tree = std::move(tree);
  loaded.lod_tree = std::move(lod);
}

// Whether `path` is a binary PLY, an SPZ, a SOG, a .ksplat or a .rad that `reading` reads part by part: always, or when
// its Gaussians as floats would take more than half of the host's memory.
bool reads_in_parts(const fs::path& path, PartReading reading) {
  const bool readable_in_parts = has_extension(path, ".ply") || has_extension(path, ".spz") ||
                                 has_extension(path, ".sog") || has_extension(path, ".ksplat") ||
                                 has_extension(path, ".rad") ||
                                 path.filename() == "meta.json";
  if (reading == PartReading::kWhole || !readable_in_parts) return false;
  if (reading == PartReading::kInParts) return true;
  const uint64_t bytes = SceneInParts::whole_scene_bytes(path);
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page_size > 0 && bytes > uint64_t(pages) * uint64_t(page_size) / 2;
}

}  // namespace

LoadedScene load_scene_file(const fs::path& path, bool strict, std::string_view program, SceneHolding holding,
                            const LodOptions& lod, PartReading reading) {
  LoadedScene loaded;
  loaded.path = path;
  require_input_file(loaded.path, "scene");
  const bool lod_set = is_lod_set(loaded.path);
  const bool lod_flags = lod.level || lod.splat_budget > 0;
  const bool lod_tree = lod_flags && !lod_set && is_lod_tree(loaded.path);
  if (!lod_set && !lod_tree && lod_flags)
    throw UsageError(std::string(lod.level ? "--lod" : "--splat-budget") +
                     " needs a LOD set (lod-meta.json) or a .rad LOD tree; " + single_quoted(path.string()) +
                     " is neither");

  const auto start = std::chrono::steady_clock::now();
  LoadOptions load_options;
  load_options.strict = strict;
  try {
    if (lod_set) {
      load_lod_set(loaded, lod, load_options);
    } else if (lod_tree) {
      load_lod_tree(loaded, lod, load_options);
    } else if (is_scene_description(loaded.path)) {
      loaded.description = load_scene_description(loaded.path);
      const bool moving = std::any_of(loaded.description->models.begin(), loaded.description->models.end(),
                                      [](const SceneModel& model) { return model.motion.has_value(); });
      if (holding == SceneHolding::kInstances || (holding == SceneHolding::kInstancesIfMoving && moving))
        loaded.instances = load_scene_instances(*loaded.description, load_options, &loaded.report);
      else
        loaded.scene = load_described_scene(*loaded.description, load_options, &loaded.report);
    } else if (reads_in_parts(loaded.path, reading)) {
      loaded.in_parts = SceneInParts::open(loaded.path, load_options, &loaded.report);
    } else {
      loaded.scene = load_scene(loaded.path, load_options, &loaded.report);
    }
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(loaded.path.string() + ": out of memory while loading the scene");
  } catch (const std::exception& error) {
    throw std::runtime_error(naming_file(loaded.path, error.what()));
  }
  loaded.load_ms = elapsed_ms(start);
  if (loaded.report.dropped > 0) {
    std::string summary = loaded.report.summary();
    if (summary.empty())
      summary = "dropped " + group_thousands(loaded.report.dropped) + " Gaussians with non-finite values";
    print_warning(program, naming_file(loaded.path, summary));
  }
  return loaded;
}

SceneViews scene_views(const LoadedScene& loaded) {
  SceneViews out;
  if (!loaded.description) return out;
  out.views = loaded.description->cameras;
  out.file = loaded.description->cameras_file.empty() ? loaded.path : loaded.description->cameras_file;
  out.lenses = loaded.description->lenses;
  out.shutters = loaded.description->shutters;
  return out;
}

Shutter shutter_at_size(const Shutter& shutter, const Camera& camera) {
  Shutter sized = shutter;
  if (sized.end_camera) sized.end_camera = resize_camera(*sized.end_camera, camera.width, camera.height);
  return sized;
}

Lighting scene_lighting(const SceneEffects& effects) {
  Lighting lighting;
  for (const SceneLight& source : effects.lights) {
    Light light;
    light.type = source.type == SceneLight::Type::kPoint ? Light::Type::kPoint : Light::Type::kDirectional;
    for (size_t c = 0; c < 3; ++c) {
      light.direction[c] = float(source.direction[c]);
      light.position[c] = float(source.position[c]);
      light.color[c] = float(source.color[c]);
    }
    light.intensity = float(source.intensity);
    lighting.lights.push_back(light);
  }
  for (size_t c = 0; c < 3; ++c) lighting.ambient[c] = float(effects.ambient[c]);
  return lighting;
}

void apply_scene_settings(const LoadedScene& loaded, RenderSettings& settings) {
  if (!loaded.description) return;
  const SceneDescription& description = *loaded.description;
  settings.background = description.background;
  settings.depth = description.outputs.depth;
  settings.splat_count = description.outputs.splat_count;
  settings.antialiasing = description.effects.antialiasing;
  settings.lighting = scene_lighting(description.effects);
  if (description.effects.sh_degree)
    settings.accuracy.sh_degree_cap =
        std::min(settings.accuracy.sh_degree_cap, *description.effects.sh_degree);
}

RenderSettings base_render_settings(const CommonOptions& options, const LoadedScene& loaded) {
  RenderSettings settings;
  if (!options.sorts.empty()) settings.sort = options.sorts.front();
  if (!options.modes.empty()) settings.accuracy = options.modes.front();  // before the scene caps its SH
  apply_scene_settings(loaded, settings);
  apply_training_options(options, settings);
  return settings;
}

std::vector<CameraView> load_camera_views(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw std::runtime_error("cannot read cameras " + single_quoted(path.string()) +
                             ": no such file or folder");
  std::vector<CameraView> views;
  try {
    views = load_camera_set(path);  // a cameras.json, a transforms.json or a COLMAP model
  } catch (const std::exception& error) {
    throw std::runtime_error(naming_file(path, error.what()));
  }
  if (views.empty()) throw std::runtime_error(single_quoted(path.string()) + " has no views");
  return views;
}

NamedCamera view_camera(const std::vector<CameraView>& views, int index, const fs::path& cameras_path,
                        int width, int height, std::string_view flag) {
  if (index < 0 || static_cast<size_t>(index) >= views.size())
    throw UsageError(std::string(flag) + " " + std::to_string(index) +
                     " is out of range: " + single_quoted(cameras_path.string()) + " has " +
                     std::to_string(views.size()) + " views (0.." + std::to_string(views.size() - 1) + ")");
  const auto& view = views[static_cast<size_t>(index)];
  check_camera_size(view.camera);
  NamedCamera named;
  named.camera = resize_camera(view.camera, width, height);
  named.description = "view " + std::to_string(index);
  if (!view.name.empty()) named.description += " (" + view.name + ")";
  named.description += " of " + cameras_path.filename().string();
  check_camera_size(named.camera);
  return named;
}

ImageSize orbit_image_size(int width, int height) {
  const double aspect = double(kOrbitDefaultWidth) / double(kOrbitDefaultHeight);
  if (width <= 0 && height <= 0) return {kOrbitDefaultWidth, kOrbitDefaultHeight};
  if (height <= 0) return {width, static_cast<int>(std::max(1.0, std::round(double(width) / aspect)))};
  if (width <= 0)
    return {static_cast<int>(
                std::min(double(kMaxImageSide) + 1, std::max(1.0, std::round(double(height) * aspect)))),
            height};
  return {width, height};
}

NamedCamera orbit_view(const LoadedScene& loaded, int width, int height, const OrbitParams& orbit) {
  if (loaded.gaussians() == 0)
    throw std::runtime_error(single_quoted(loaded.path.string()) +
                             " has no Gaussians for the orbit camera to frame; pass --cameras FILE.json");
  const ImageSize size = orbit_image_size(width, height);
  NamedCamera named;
  named.camera = orbit_camera(loaded.bounds(), size.width, size.height, orbit);
  named.description = "orbit azimuth " + format_fixed(orbit.azimuth_deg, 1) + " elevation " +
                      format_fixed(orbit.elevation_deg, 1) + " fov " +
                      format_fixed(orbit.vertical_fov_deg, 1);
  check_camera_size(named.camera);
  return named;
}

SceneViews camera_views(const CommonOptions& options, const LoadedScene& loaded) {
  if (options.cameras.empty()) return scene_views(loaded);
  return {load_camera_views(options.cameras), options.cameras};
}

LoadedScene load_scene_and_camera(const CommonOptions& options, std::string_view program,
                                  SceneHolding holding, PartReading reading) {
  LoadedScene loaded = load_scene_file(options.scene, options.strict, program, holding, options.lod, reading);
  const SceneViews cameras = camera_views(options, loaded);
  NamedCamera named;
  if (!cameras.views.empty()) {
    if (options.cameras.empty() && options.orbit_given)
      throw UsageError("--azimuth, --elevation, --fov and --distance apply only to the orbit camera, and " +
                       single_quoted(loaded.path.string()) +
                       " has cameras of its own (pick one with --view)");
    named = view_camera(cameras.views, options.view, cameras.file, options.width, options.height);
    loaded.view_index = options.view;
    loaded.view_name = cameras.views[size_t(options.view)].name;  // in range: view_camera checked it
    if (!cameras.lenses.empty()) loaded.lens = cameras.lenses[size_t(options.view)];
    if (!cameras.shutters.empty())
      loaded.shutter = shutter_at_size(cameras.shutters[size_t(options.view)], named.camera);
  } else {
    if (options.view_given)
      throw UsageError(
          "--view needs cameras: " + single_quoted(loaded.path.string()) +
          " has none, and no --cameras FILE.json was given (without them the camera is an orbit)");
    named = orbit_view(loaded, options.width, options.height, options.orbit);
  }
  loaded.camera = named.camera;
  loaded.camera_description = named.description;
  return loaded;
}

std::string describe_scene(const GaussianScene& scene) {
  return group_thousands(scene.size()) + " Gaussians (SH" + std::to_string(scene.sh_degree) + ")";
}

std::string describe_scene(const LoadedScene& loaded) {
  if (loaded.lod) {
    const LodSet& set = *loaded.lod->set;
    std::string levels;
    for (int level = 0; level < set.levels(); ++level)
      levels += (level ? " / " : "") + group_thousands(set.level_size(level));
    const std::string what =
        "LOD set of " + std::to_string(set.levels()) + " levels (" + levels + " Gaussians)";
    if (loaded.lod->splat_budget > 0)
      return what + ", at most " + group_thousands(loaded.lod->splat_budget) + " a frame";
    return what + ", level " + std::to_string(loaded.lod->level) + ": " + describe_scene(loaded.scene);
  }
  if (loaded.lod_tree) {
    const SplatLodTree& tree = *loaded.lod_tree->tree;
    const std::string what = "LOD tree of " + group_thousands(tree.nodes()) + " splats (" +
                             group_thousands(tree.level_nodes(0).size()) + " leaves, " +
                             std::to_string(tree.levels()) + " levels, SH" + std::to_string(tree.sh_degree()) + ")";
    if (loaded.lod_tree->splat_budget > 0)
      return what + ", at most " + group_thousands(loaded.lod_tree->splat_budget) + " a frame";
    return what + ", level " + std::to_string(loaded.lod_tree->level) + ": " + describe_scene(loaded.scene);
  }
  if (loaded.in_parts)
    return group_thousands(loaded.in_parts->size()) + " Gaussians (SH" +
           std::to_string(loaded.in_parts->sh_degree()) + "), read in parts from " +
           (loaded.report.format == "spz"             ? "its packed bytes"
            : loaded.report.format.starts_with("sog") ? "its images' texels"
                                                      : "the file");
  if (!loaded.instances) return describe_scene(loaded.scene);
  return group_thousands(loaded.gaussians()) + " Gaussians (SH" +
         std::to_string(loaded.instances->sh_degree) + "), " +
         std::to_string(loaded.instances->instances.size()) + " placed copies of " +
         std::to_string(loaded.instances->files.size()) +
         (loaded.instances->files.size() == 1 ? " file" : " files");
}

}  // namespace tilesplat::cli
