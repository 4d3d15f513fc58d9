// Loading what the command line names: the scene (a splat file or a scene file), its cameras, and
// the camera of the frame, with errors that name the file.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "arg_parser.h"
#include "common_options.h"
#include "tilesplat/camera.h"
#include "tilesplat/lens.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/lod_tree.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat::cli {

// How a scene file's models are held: merged into one scene, or as placed copies of their files (for a
// renderer under a memory budget, which places the copies part by part: docs/big-scenes.md), or so only
// when some of them move (a merged scene is where they are at time 0: the renderer places moving copies
// at each time of a shutter, docs/effects.md).
enum class SceneHolding { kMerged, kInstances, kInstancesIfMoving };

// How a binary PLY, an SPZ or a SOG is held: read whole (load_scene), or read part by part as the frames draw
// it (SceneInParts: its positions held, and an SPZ's packed bytes or a SOG's texels), always or when its
// Gaussians as floats would take more than half of the host's memory (tilesplat-render, --read-in-parts).
enum class PartReading { kWhole, kInPartsWhenLarge, kInParts };

// A LOD set the SCENE names (lod-meta.json): the index, and how the run draws it.
struct LoadedLodSet {
  std::shared_ptr<const LodSet> set;
  int level = 0;              // the level in LoadedScene::scene (unused under a splat budget)
  uint64_t splat_budget = 0;  // > 0: each frame draws select_lod_levels(set, camera, splat_budget)
  // Every level frames the same: an orbit frames the set by its coarsest level (the cheapest to read),
  // so that renders of one orbit at different levels and budgets show the same view.
  Bounds framing;
};

// A .rad LOD tree the SCENE names, drawn at one level (--lod, held in LoadedScene::scene) or under a splat
// budget (each frame draws SplatLodTree::select's cut for its camera).
struct LoadedLodTree {
  std::shared_ptr<const SplatLodTree> tree;
  int level = 0;
  uint64_t splat_budget = 0;
  Bounds framing;  // the leaves': every level and budget frames the same view
};

struct LoadedScene {
  std::filesystem::path path;
  GaussianScene scene;
  // Set when the SCENE is a scene file (.json, docs/scene-format.md): its cameras, background,
  // effects and outputs. Its models are already loaded, transformed and merged into `scene`, or, held
  // as SceneHolding::kInstances, placed in `instances` (and `scene` is empty).
  std::optional<SceneDescription> description;
  std::optional<SceneInstances> instances;
  // Set when a binary PLY, an SPZ or a SOG is read part by part (PartReading): `scene` is empty.
  std::optional<SceneInParts> in_parts;
  // Set when the SCENE is a LOD set: `scene` holds its level lod->level, or nothing under a splat budget.
  std::optional<LoadedLodSet> lod;
  // Set when the SCENE is a .rad LOD tree drawn with --lod or --splat-budget (without them it is read as
  // any file: its leaves, in `scene`). `scene` holds the level, or nothing under a splat budget.
  std::optional<LoadedLodTree> lod_tree;
  size_t gaussians() const;  // what a frame draws at most (under a splat budget: the finest level's size)
  Bounds bounds() const;     // what an orbit frames
  LoadReport report;
  Camera camera;
  std::string camera_description;  // "view 0 of cams.json" or "orbit azimuth 0 elevation 20 fov 50"
  std::optional<int> view_index;   // the view's index in its cameras, when the camera is a view
  std::string view_name;           // its img_name (may be empty); empty for the orbit camera
  ThinLens lens;                   // the scene file's lens for that view (SceneDescription::lenses); off else
  Shutter shutter;  // the scene file's shutter for that view (SceneDescription::shutters), its end camera
                    // at the view's size; closed else
  double load_ms = 0;
};

// Loads the scene (printing LoadReport::summary() to stderr as a warning when Gaussians were
// dropped) and builds the camera at the requested size: --cameras, else the scene file's cameras,
// else the orbit. A missing or unreadable file throws std::runtime_error naming it; an
// out-of-range --view throws UsageError naming the file and its number of views.
LoadedScene load_scene_and_camera(const CommonOptions& options, std::string_view program,
                                  SceneHolding holding = SceneHolding::kMerged,
                                  PartReading reading = PartReading::kWhole);

// The parts of load_scene_and_camera, for an app that renders several cameras of a scene.
// load_scene_file fills path, scene, description, report and load_ms only.
// A LOD set or a .rad LOD tree is read as `lod` says; `lod` given for any other scene is a UsageError.
LoadedScene load_scene_file(const std::filesystem::path& path, bool strict, std::string_view program,
                            SceneHolding holding = SceneHolding::kMerged, const LodOptions& lod = {},
                            PartReading reading = PartReading::kWhole);

// The views a scene file brings ("cameras") and the file that names them (the cameras.json it
// refers to, else the scene file). No views for a .ply, or a scene file without cameras.
struct SceneViews {
  std::vector<CameraView> views;
  std::filesystem::path file;
  std::vector<ThinLens> lenses;  // the scene file's, one per view; empty for --cameras and cameras.json
  std::vector<Shutter> shutters;  // likewise
};
// A view's shutter (SceneViews::shutters) for its camera at another size (view_camera): the end camera
// resized the same way.
Shutter shutter_at_size(const Shutter& shutter, const Camera& camera);
SceneViews scene_views(const LoadedScene& loaded);
// The views a run picks from: those of --cameras (loaded) when given, else the scene file's own.
// No views when neither has any.
SceneViews camera_views(const CommonOptions& options, const LoadedScene& loaded);

// A scene file's lights and ambient as the renderer's Lighting (off when the file has no lights).
Lighting scene_lighting(const SceneEffects& effects);

// What a scene file asks of every frame: its background, its outputs (depth, splat_count), its
// antialiasing, its lights (lighting) and its sh_degree effect (accuracy.sh_degree_cap: the smaller
// of it and the --mode's cap). A .ply leaves the settings as they are. Flags that override the scene
// file are applied after this.
void apply_scene_settings(const LoadedScene& loaded, RenderSettings& settings);

// The settings an app starts its frames from, built in this order: the first --sort and --mode, the scene
// file's settings (apply_scene_settings: its sh_degree caps the mode's), then the flags that override the
// file (apply_training_options: --antialiasing, --max-alpha, --compositor). Each app then adds what is its
// own (tilesplat-render's --region and outputs, the bench's sort per row, the viewer's key cycles).
RenderSettings base_render_settings(const CommonOptions& options, const LoadedScene& loaded);

// The views of a camera set: a cameras.json, a transforms.json or a COLMAP model (folder or file;
// tilesplat::load_camera_set). Throws std::runtime_error naming the file when it is missing,
// malformed or has no views.
std::vector<CameraView> load_camera_views(const std::filesystem::path& path);

struct NamedCamera {
  Camera camera;
  std::string description;  // as LoadedScene::camera_description
};
// View `index` of `views` (read from `cameras_path`) at width x height (0: see CommonOptions).
// An out-of-range index throws UsageError naming `flag`, the file and its number of views.
NamedCamera view_camera(const std::vector<CameraView>& views, int index,
                        const std::filesystem::path& cameras_path, int width, int height,
                        std::string_view flag = "--view");
// The size of a camera of its own making (orbit, path) for --width W --height H (0: not given):
// 1920x1080 by default, one side given keeps that aspect.
ImageSize orbit_image_size(int width, int height);
// The orbit camera framing the scene (which must not be empty) at width x height (0: see CommonOptions).
NamedCamera orbit_view(const LoadedScene& loaded, int width, int height, const OrbitParams& orbit);

// "SH3" style summary of the scene: "64 Gaussians (SH3)"; of a loaded scene held either way.
std::string describe_scene(const GaussianScene& scene);
std::string describe_scene(const LoadedScene& loaded);

}  // namespace tilesplat::cli
