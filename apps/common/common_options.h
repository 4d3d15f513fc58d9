// The options every app has: which scene, which camera, which device, which sort and accuracy modes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"

namespace tilesplat::cli {

// How a LOD set (lod-meta.json, tilesplat/lod_set.h) is drawn: one level for every frame, or, under a
// splat budget, the levels each frame's camera calls for (select_lod_levels).
struct LodOptions {
  std::optional<int> level;   // --lod N (default 0: the finest)
  uint64_t splat_budget = 0;  // --splat-budget N: levels chosen per frame (0: none; where the app offers it)
};

struct CommonOptions {
  std::string scene;
  std::string cameras;
  // With SceneChoice::kList, every SCENE and every --cameras in command-line order, and scene and
  // cameras stay empty.
  std::vector<std::string> scenes;
  std::vector<std::string> cameras_files;
  int view = 0;
  bool view_given = false;  // --view appeared (a scene file's cameras make it valid without --cameras)
  int width = 0;  // 0: the view's size (or kOrbitDefaultWidth), keeping the aspect when one is given
  int height = 0;
  OrbitParams orbit;
  bool orbit_given = false;  // an orbit flag (--azimuth, --elevation, --fov, --distance) appeared
  bool strict = false;
  std::string device;
  bool list_devices = false;
  bool validation = false;
  std::vector<std::string> sorts;  // validated against sort_strategies(); empty = the app's default
  // --mode: accuracy mode combinations (parse_accuracy_modes); empty = the reference alone.
  std::vector<AccuracyModes> modes;
  // --antialiasing: the footprint filter the asset was trained with; unset = the scene file's, else classic.
  std::optional<Antialiasing> antialiasing;
  // --max-alpha: the cap on a splat's alpha the asset was trained with; unset = kDefaultMaxAlpha.
  std::optional<double> max_alpha;
  // --compositor: how the splats become pixels; unset = the app's default (sorted).
  std::optional<Compositor> compositor;
  LodOptions lod;  // --lod (every app), --splat-budget (add_splat_budget_option)
};

inline constexpr int kOrbitDefaultWidth = 1920;
inline constexpr int kOrbitDefaultHeight = 1080;

enum class SortChoice { kOne, kList };
// kList: one or more SCENE arguments, and --cameras may be given several times.
enum class SceneChoice { kOne, kList };

// Declares SCENE, --cameras, --view, --width, --height, the orbit flags, --strict, --device,
// --list-devices, --validation, --sort (one name, or a comma list / "all" for kList) and --mode
// (one accuracy mode combination, or a comma list of them for kList), --antialiasing, --max-alpha and
// --compositor.
void add_common_options(ArgParser& parser, CommonOptions& options, SortChoice sort_choice,
                        SceneChoice scene_choice = SceneChoice::kOne);

// Loads the sort plugins that --sort-plugin FILE names (tilesplat::load_sort_plugin), before the
// parser is built: their strategies must be known when --sort is checked and --help lists the
// names. add_common_options declares the flag itself for --help. Throws what loading throws.
void load_sort_plugins(int argc, const char* const* argv);

// Checks what the parser cannot check flag by flag (a SCENE was given, orbit flags are not
// mixed with --cameras, --view has cameras to pick from, ...). Throws UsageError.
void check_common_options(const ArgParser& parser, const CommonOptions& options);

// parse_and_handle_help, and --list-devices.
bool parse_and_handle_info_flags(ArgParser& parser, int argc, const char* const* argv,
                                 const CommonOptions& common);

// Prints list_devices() with the indices --device accepts.
void print_devices();

RendererOptions renderer_options(const CommonOptions& options);

// What the flags say of how the splats were trained (--antialiasing, --max-alpha), over `settings`
// (which hold the scene file's), and of how they become pixels (--compositor).
void apply_training_options(const CommonOptions& options, RenderSettings& settings);

// --memory-budget SIZE (parse_byte_size) into `budget`, RenderSettings::memory_budget; `what_it_adds`
// ends the help text with what the app does besides rendering in parts.
void add_memory_budget_option(ArgParser& parser, uint64_t& budget, const std::string& what_it_adds);

// --fisheye, --orthographic and --equirectangular: every frame's camera (its pose, size and principal point)
// through another model. Off: the cameras as given, whatever model they have.
struct CameraModelFlags {
  std::optional<double> fisheye_fov_deg;  // --fisheye DEG: equidistant, DEG across the shorter side
  std::optional<double> view_height;      // --orthographic H: H world units tall
  bool equirectangular = false;           // --equirectangular: the 360x180 panorama
  int given() const { return fisheye_fov_deg.has_value() + view_height.has_value() + equirectangular; }
  bool enabled() const { return given() > 0; }
  bool operator==(const CameraModelFlags&) const = default;
};
// Declares the three flags, in a section of their own.
void add_camera_model_options(ArgParser& parser, CameraModelFlags& flags);
// Throws UsageError for more than one of them.
void check_camera_model_options(const CameraModelFlags& flags);
// The frame's camera through the flags' model (fisheye_camera, orthographic_camera), or as it is.
Camera camera_for_frame(const CameraModelFlags& flags, const Camera& camera);

// --splat-budget N into options.lod.splat_budget, for an app that renders a LOD set frame by frame.
void add_splat_budget_option(ArgParser& parser, CommonOptions& options);

// Whether any SCENE of the options is a scene file (.json).
bool any_scene_file(const CommonOptions& options);

}  // namespace tilesplat::cli
