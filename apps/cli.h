// What tilesplat-render and tilesplat-bench share: a small declarative flag parser, the
// "scene + camera + device" options and error reporting with the apps' exit codes. Text outputs are
// written with tilesplat::write_file_atomically (tilesplat/image.h), as the engine writes its images.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"

namespace tilesplat::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // a runtime error: a bad file, a failed render or write
inline constexpr int kExitUsage = 2;    // a command-line mistake

// A mistake on the command line: reported like any error but exits with kExitUsage.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The largest width or height the apps accept before asking the device (which has its own limit).
inline constexpr int kMaxImageSide = 65536;

// Declarative parser: flags are registered with their help text, so --help lists exactly what
// the parser accepts. Value flags take "--flag value" or "--flag=value"; "--" ends the flags.
class ArgParser {
 public:
  enum class Outcome { kRun, kHelp, kVersion };

  ArgParser(std::string program, std::string usage, std::string description);

  // Flags registered after this call are listed under `title` in --help.
  void section(std::string title);

  // A flag with a value. on_value throws UsageError when the text is not acceptable.
  // short_name is e.g. "-o" (may be empty).
  void add_value(std::string name, std::string value_name, std::string help,
                 std::function<void(const std::string&)> on_value, std::string short_name = {});
  void add_string(std::string name, std::string value_name, std::string help, std::string* target,
                  std::string short_name = {});
  // An integer in [min, max]; see parse_int for the messages.
  void add_int(std::string name, std::string value_name, std::string help, int* target, int min, int max);
  // Any finite number.
  void add_double(std::string name, std::string value_name, std::string help, double* target);
  // A boolean switch: present = true. It takes no value.
  void add_switch(std::string name, std::string help, bool* target);
  // Positional arguments fill their targets in registration order.
  void add_positional(std::string value_name, std::string help, std::string* target);
  // Takes every positional argument left over (register it last); shown as "VALUE_NAME..." in --help.
  void add_positional_list(std::string value_name, std::string help, std::vector<std::string>* target);

  // Throws UsageError. Returns kHelp (without parsing anything else) when -h/--help is given, else
  // kVersion when --version is.
  Outcome parse(int argc, const char* const* argv);

  // Whether the flag (its long name) appeared on the command line.
  bool seen(std::string_view name) const { return seen_.count(std::string(name)) != 0; }

  std::string help_text() const;
  const std::string& program() const { return program_; }

 private:
  struct Option {
    std::string name;
    std::string short_name;
    std::string value_name;  // empty for switches
    std::string help;
    std::function<void(const std::string&)> on_value;
    bool* switch_target = nullptr;
    size_t section = 0;
  };
  struct Positional {
    std::string value_name;
    std::string help;
    std::string* target = nullptr;
    std::vector<std::string>* list_target = nullptr;  // set instead of target by add_positional_list
  };

  const Option* find(std::string_view name) const;

  std::string program_;
  std::string usage_;
  std::string description_;
  std::vector<std::string> sections_;
  std::vector<Option> options_;
  std::vector<Positional> positionals_;
  std::set<std::string> seen_;
};

// Value parsers shared by the flags; all throw UsageError naming the flag and the text.
// "--width expects a positive integer, got 'abc'"; "--width must be at most 65536, got '70000'".
int parse_int(std::string_view flag, std::string_view text, int min, int max);
double parse_double(std::string_view flag, std::string_view text);
// "r,g,b": three finite floats.
std::array<float, 3> parse_rgb(std::string_view flag, std::string_view text);
std::vector<std::string> split(std::string_view text, char separator);

struct ImageSize {
  int width = 0;
  int height = 0;
  bool operator==(const ImageSize&) const = default;
};
// "WxH[,WxH...]", each side 1 to kMaxImageSide; a repeated size is kept once, the order is kept.
// "--resolutions expects WxH sizes from 1x1 to 65536x65536, comma-separated (e.g. 1920x1080,1280x720),
// got '0x720' in '1920x1080,0x720'".
std::vector<ImageSize> parse_resolutions(std::string_view flag, std::string_view text);
std::string format_size(int width, int height);  // "1920x1080"

// The options every app has: which scene, which camera, which device.
struct CommonOptions {
  std::string scene;
  std::string cameras;
  // With SceneChoice::kList, every SCENE and every --cameras in command-line order, and scene and
  // cameras stay empty.
  std::vector<std::string> scenes;
  std::vector<std::string> cameras_files;
  int view = 0;
  bool view_given = false;   // --view appeared (a scene file's cameras make it valid without --cameras)
  int width = 0;   // 0: the view's size (or kOrbitDefaultWidth), keeping the aspect when one is given
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
};

inline constexpr int kOrbitDefaultWidth = 1920;
inline constexpr int kOrbitDefaultHeight = 1080;

enum class SortChoice { kOne, kList };
// kList: one or more SCENE arguments, and --cameras may be given several times.
enum class SceneChoice { kOne, kList };

// Registers SCENE, --cameras, --view, --width, --height, the orbit flags, --strict, --device,
// --list-devices, --validation, --sort (one name, or a comma list / "all" for kList) and --mode
// (one accuracy mode combination, or a comma list of them for kList), and --antialiasing.
void add_common_options(ArgParser& parser, CommonOptions& options, SortChoice sort_choice,
                        SceneChoice scene_choice = SceneChoice::kOne);

// Loads the sort plugins that --sort-plugin FILE names (tilesplat::load_sort_plugin), before the
// parser is built: their strategies must be known when --sort is checked and --help lists the
// names. add_common_options registers the flag itself for --help. Throws what loading throws.
void load_sort_plugins(int argc, const char* const* argv);

// Checks what the parser cannot check flag by flag (a SCENE was given, orbit flags are not
// mixed with --cameras, --view has cameras to pick from, ...). Throws UsageError.
void check_common_options(const ArgParser& parser, const CommonOptions& options);

// Prints list_devices() with the indices --device accepts.
void print_devices();

// "tilesplat-render 0.3.0 (commit 1a2b3c..., Release)": the library's version and build.
std::string version_text(std::string_view program);

// The command as typed ("tilesplat-bench a.ply --csv c.csv"), for the outputs that record how they
// were made. Arguments with spaces or quotes are single-quoted so that a shell runs it again.
std::string command_line(std::string_view program, int argc, const char* const* argv);

// A CSV table with four provenance columns appended to every record: tilesplat_version,
// tilesplat_commit, build_type (build_info()) and command. Every row carries them, so the rows of
// runs concatenated into one table still say which build and command produced each.
std::string with_provenance_columns(const std::string& csv, const std::string& command);

// Parses the command line and handles --help and --version, which end the program before it does
// any work. Returns true when the program should exit with kExitOk.
bool parse_and_handle_help(ArgParser& parser, int argc, const char* const* argv);

// The same, and --list-devices.
bool parse_and_handle_info_flags(ArgParser& parser, int argc, const char* const* argv,
                                 const CommonOptions& common);

struct LoadedScene {
  std::filesystem::path path;
  GaussianScene scene;
  // Set when the SCENE is a scene file (.json, docs/scene-format.md): its cameras, background,
  // effects and outputs. Its models are already loaded, transformed and merged into `scene`.
  std::optional<SceneDescription> description;
  LoadReport report;
  Camera camera;
  std::string camera_description;  // "view 0 of cams.json" or "orbit azimuth 0 elevation 20 fov 50"
  std::optional<int> view_index;   // the view's index in its cameras, when the camera is a view
  std::string view_name;           // its img_name (may be empty); empty for the orbit camera
  double load_ms = 0;
};

// Loads the scene (printing LoadReport::summary() to stderr as a warning when Gaussians were
// dropped) and builds the camera at the requested size: --cameras, else the scene file's cameras,
// else the orbit. A missing or unreadable file throws std::runtime_error naming it; an
// out-of-range --view throws UsageError naming the file and its number of views.
LoadedScene load_scene_and_camera(const CommonOptions& options, std::string_view program);

// The parts of load_scene_and_camera, for an app that renders several cameras of a scene.
// load_scene_file fills path, scene, description, report and load_ms only.
LoadedScene load_scene_file(const std::filesystem::path& path, bool strict, std::string_view program);

// The views a scene file brings ("cameras") and the file that names them (the cameras.json it
// refers to, else the scene file). No views for a .ply, or a scene file without cameras.
struct SceneViews {
  std::vector<CameraView> views;
  std::filesystem::path file;
};
SceneViews scene_views(const LoadedScene& loaded);
// The views a run picks from: those of --cameras (loaded) when given, else the scene file's own.
// No views when neither has any.
SceneViews camera_views(const CommonOptions& options, const LoadedScene& loaded);

// A scene file's lights and ambient as the renderer's Lighting (off when the file has no lights).
Lighting scene_lighting(const SceneEffects& effects);

// What a scene file asks of every frame: its background, its outputs (depth, splat_count), its
// antialiasing, its lights (lighting) and its sh_degree effect (accuracy.sh_degree_cap: the smaller
// of it and the --mode's cap). A .ply
// leaves the settings as they are. Flags that override the scene file are applied after this.
void apply_scene_settings(const LoadedScene& loaded, RenderSettings& settings);

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
NamedCamera view_camera(const std::vector<CameraView>& views, int index, const std::filesystem::path& cameras_path,
                        int width, int height, std::string_view flag = "--view");
// The size of a camera of its own making (orbit, path) for --width W --height H (0: not given):
// 1920x1080 by default, one side given keeps that aspect.
ImageSize orbit_image_size(int width, int height);
// The orbit camera framing the scene (which must not be empty) at width x height (0: see CommonOptions).
NamedCamera orbit_view(const LoadedScene& loaded, int width, int height, const OrbitParams& orbit);

RendererOptions renderer_options(const CommonOptions& options);

// Whether any SCENE of the options is a scene file (.json).
bool any_scene_file(const CommonOptions& options);

// "SH3" style summary of the scene: "64 Gaussians (SH3)".
std::string describe_scene(const GaussianScene& scene);

// Runs an app's body, turning exceptions into one line "PROGRAM: error: MESSAGE" on stderr and
// the exit codes above.
int run_app(std::string_view program, const std::function<int()>& body);
void print_error(std::string_view program, std::string_view message);
void print_warning(std::string_view program, std::string_view message);

// Fails early (std::runtime_error) when `path` cannot be an output: its directory does not
// exist, or it names a directory. `flag` names the option in the message.
void check_output_path(const std::filesystem::path& path, std::string_view flag);
// Throws UsageError when two of the given (flag, path) pairs name the same file; empty paths
// are skipped. Keeps an output from overwriting an input or another output.
void check_distinct_paths(const std::vector<std::pair<std::string, std::filesystem::path>>& paths);
// Whether the path's extension is `extension` (".exr"), ignoring case.
bool has_extension(const std::filesystem::path& path, std::string_view extension);


// Collapses an exception message to one line.
std::string one_line(std::string_view message);
// Fixed-point number with `decimals` digits.
std::string format_fixed(double value, int decimals);
// The same, with "inf", "-inf" and "nan" for the values that have no digits (a PSNR of identical images).
std::string format_number(double value, int decimals);
// The median of the values (the mean of the middle two for an even count); 0 for none.
double median(std::vector<double> values);
// A CSV field: quoted (quotes doubled) when it holds a comma, quote or line break.
std::string csv_field(const std::string& text);
bool stderr_is_terminal();

// The process's peak resident memory since the last reset_peak_memory(), in bytes (Linux: VmHWM,
// reset through /proc/self/clear_refs after returning freed heap memory to the system; 0 where that
// cannot be read).
void reset_peak_memory();
uint64_t peak_memory_bytes();
uint64_t resident_memory_bytes();

}  // namespace tilesplat::cli
