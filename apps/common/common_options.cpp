#include "common_options.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "text.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/sort_strategy.h"

namespace tilesplat::cli {

namespace {

std::vector<std::string> available_sorts() {
  try {
    return sort_strategies();
  } catch (const std::exception&) {
    return {};
  }
}

std::string sort_name_checked(std::string_view flag, const std::string& name,
                              const std::vector<std::string>& available) {
  const std::string trimmed = trim(name);
  if (std::find(available.begin(), available.end(), trimmed) == available.end())
    throw UsageError("unknown sort strategy " + single_quoted(trimmed) + " for " + std::string(flag) +
                     " (available: " + join(available, ", ") + ")");
  return trimmed;
}

}  // namespace

void load_sort_plugins(int argc, const char* const* argv) {
  constexpr std::string_view kFlag = "--sort-plugin";
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    if (argument == "--") break;
    if (argument == kFlag && i + 1 < argc) {
      tilesplat::load_sort_plugin(argv[++i]);
    } else if (argument.size() > kFlag.size() + 1 && argument.starts_with(kFlag) &&
               argument[kFlag.size()] == '=') {
      tilesplat::load_sort_plugin(std::string(argument.substr(kFlag.size() + 1)));
    }
  }
}

void add_common_options(ArgParser& parser, CommonOptions& options, SortChoice sort_choice,
                        SceneChoice scene_choice) {
  const OrbitParams orbit_defaults;
  const std::string cameras_help =
      "take the camera from a camera set: the trainer's cameras.json, a nerfstudio/instant-ngp "
      "transforms.json, "
      "or a COLMAP sparse model (its folder, or its cameras/images .bin or .txt) (default: an orbit camera "
      "framing the scene, see --azimuth)";
  if (scene_choice == SceneChoice::kOne) {
    parser.add_positional(
        "SCENE.ply",
        "the scene: a 3D Gaussian Splatting file (.ply, .compressed.ply, .splat, .spz, .sog, SOG meta.json, "
        ".glb, .gltf; docs/formats.md), or a scene file "
        "(.json, docs/scene-format.md) that places several of them and brings cameras, "
        "background and outputs",
        &options.scene);
  } else {
    parser.add_positional_list(
        "SCENE.ply",
        "the scenes: 3D Gaussian Splatting .ply files as the trainer writes them, or scene "
        "files (.json, docs/scene-format.md), each loaded once",
        &options.scenes);
  }

  parser.section("camera");
  if (scene_choice == SceneChoice::kOne) {
    parser.add_string("--cameras", "CAMERAS", cameras_help, &options.cameras);
  } else {
    parser.add_value("--cameras", "CAMERAS",
                     cameras_help + "; give it once for every SCENE, or once per SCENE in the same order",
                     [&options](const std::string& text) {
                       if (text.empty()) throw UsageError("--cameras expects a value, got an empty string");
                       options.cameras_files.push_back(text);
                     });
  }
  parser.add_value("--view", "N",
                   "which view of --cameras (or of a scene file's cameras), counting from 0 (default 0)",
                   [&options](const std::string& text) {
                     options.view = parse_int("--view", text, 0, std::numeric_limits<int>::max());
                     options.view_given = true;
                   });
  parser.add_int("--width", "W",
                 "image width in pixels; given alone, the height follows the view's aspect ratio (default: "
                 "the view's size, or 1920x1080 for the orbit camera)",
                 &options.width, 1, kMaxImageSide);
  parser.add_int("--height", "H", "image height in pixels; given alone, the width follows the aspect ratio",
                 &options.height, 1, kMaxImageSide);
  parser.add_value(
      "--azimuth", "DEG",
      "orbit camera: angle around the scene (default " + format_fixed(orbit_defaults.azimuth_deg, 0) + ")",
      [&options](const std::string& text) {
        options.orbit.azimuth_deg = parse_double("--azimuth", text);
        options.orbit_given = true;
      });
  parser.add_value(
      "--elevation", "DEG",
      "orbit camera: angle above the horizon, between -90 and 90 (default " +
          format_fixed(orbit_defaults.elevation_deg, 0) + ")",
      [&options](const std::string& text) {
        const double degrees = parse_double("--elevation", text);
        if (!(degrees > -90 && degrees < 90))
          throw UsageError("--elevation must be strictly between -90 and 90, got " + single_quoted(text));
        options.orbit.elevation_deg = degrees;
        options.orbit_given = true;
      });
  parser.add_value(
      "--fov", "DEG",
      "orbit camera: vertical field of view (default " + format_fixed(orbit_defaults.vertical_fov_deg, 0) +
          ")",
      [&options](const std::string& text) {
        const double degrees = parse_double("--fov", text);
        if (!(degrees > 0 && degrees < 180))
          throw UsageError("--fov must be strictly between 0 and 180 degrees, got " + single_quoted(text));
        options.orbit.vertical_fov_deg = degrees;
        options.orbit_given = true;
      });
  parser.add_value("--distance", "SCALE",
                   "orbit camera: multiply the distance that frames the scene (default 1)",
                   [&options](const std::string& text) {
                     const double scale = parse_double("--distance", text);
                     if (!(scale > 0))
                       throw UsageError("--distance must be positive, got " + single_quoted(text));
                     options.orbit.distance_scale = scale;
                     options.orbit_given = true;
                   });

  parser.section("scene and device");
  parser.add_value("--lod", "N",
                   "a LOD set (splat-transform's lod-meta.json) or a .rad LOD tree (Spark's build-lod): draw "
                   "its level N, 0 the finest (default 0; docs/big-scenes.md)",
                   [&options](const std::string& text) {
                     options.lod.level = parse_int("--lod", text, 0, std::numeric_limits<int>::max());
                   });
  parser.add_switch(
      "--strict",
      "fail on the first non-finite value in the scene (default: drop such Gaussians and report "
      "them)",
      &options.strict);
  parser.add_string(
      "--device", "INDEX|NAME|UUID",
      "Vulkan device: an index from --list-devices, part of its name, or its UUID (on NVIDIA the GPU "
      "UUID a scheduler assigns; default: $TILESPLAT_DEVICE, else the first discrete GPU, else the "
      "first device)",
      &options.device);
  parser.add_switch("--list-devices", "print the Vulkan devices with their indices and exit",
                    &options.list_devices);
  parser.add_switch(
      "--validation",
      "enable the Khronos validation layer and report its messages (also TILESPLAT_VALIDATION=1)",
      &options.validation);

  parser.add_value("--sort-plugin", "FILE.so",
                   "load the sort strategies of a plugin (tilesplat/sort_strategy.h) before --sort is read; "
                   "repeatable",
                   [](const std::string&) {});  // loaded by load_sort_plugins before parsing
  const auto strategies = available_sorts();
  // "auto" picks one of them per device (RenderSettings::sort); 'all' measures each of them.
  std::vector<std::string> available = {"auto"};
  available.insert(available.end(), strategies.begin(), strategies.end());
  if (sort_choice == SortChoice::kOne) {
    parser.add_value("--sort", "NAME",
                     "key sort strategy: " + join(available, ", ") +
                         " (default auto: the fastest for the device, cpu-radix on a CPU driver, onesweep on "
                         "NVIDIA, radix on other GPUs; the same image whichever)",
                     [&options, available](const std::string& text) {
                       options.sorts = {sort_name_checked("--sort", text, available)};
                     });
  } else {
    parser.add_value(
        "--sort", "NAME[,NAME...]",
        "key sort strategies to measure, comma-separated, or 'all' (every one but auto): " +
            join(available, ", ") + " (default all)",
        [&options, available, strategies](const std::string& text) {
          options.sorts.clear();
          for (const auto& part : split(text, ',')) {
            if (trim(part) == "all") {
              for (const auto& name : strategies)
                if (std::find(options.sorts.begin(), options.sorts.end(), name) == options.sorts.end())
                  options.sorts.push_back(name);
              continue;
            }
            if (trim(part).empty())
              throw UsageError("--sort expects comma-separated names, got " + single_quoted(text));
            const auto name = sort_name_checked("--sort", part, available);
            if (std::find(options.sorts.begin(), options.sorts.end(), name) == options.sorts.end())
              options.sorts.push_back(name);
          }
        });
  }

  const std::string modes_help =
      "reference, depth24, depth16, radial, opacity-extent, square-tiles, sh0..sh3, fp16-sh, "
      "fp16-cov, t-cutoff=X, alpha-cutoff=X (X a number or 1/64), resortN (2-16), fp16-blend (raster); "
      "combine with '+'";
  auto parse_modes = [](const std::string& text) {
    try {
      return parse_accuracy_modes(std::string(trim(text)));
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--mode: ") + e.what());
    }
  };
  if (sort_choice == SortChoice::kOne) {
    parser.add_value(
        "--mode", "MODES", "accuracy modes (default reference): " + modes_help,
        [&options, parse_modes](const std::string& text) { options.modes = {parse_modes(text)}; });
  } else {
    parser.add_value(
        "--mode", "MODES[,MODES...]",
        "accuracy mode combinations to measure, comma-separated (default reference): " + modes_help,
        [&options, parse_modes](const std::string& text) {
          options.modes.clear();
          for (const auto& part : split(text, ',')) {
            const AccuracyModes modes = parse_modes(part);
            if (std::find(options.modes.begin(), options.modes.end(), modes) == options.modes.end())
              options.modes.push_back(modes);
          }
        });
  }
  parser.add_value(
      "--antialiasing", "MODE",
      "the footprint filter the splats were trained with: classic (3DGS), antialiased (gsplat) or "
      "mip (Mip-Splatting) (default: the scene file's, else classic)",
      [&options](const std::string& text) {
        for (Antialiasing mode : {Antialiasing::kClassic, Antialiasing::kAntialiased, Antialiasing::kMip})
          if (text == to_string(mode)) {
            options.antialiasing = mode;
            return;
          }
        throw UsageError("--antialiasing must be classic, antialiased or mip, got " + single_quoted(text));
      });
  parser.add_value(
      "--compositor", "NAME",
      "how the splats become pixels: sorted (each tile's depth-sorted list blended in a compute "
      "pass; the default), stochastic (sort-free, averaged) or raster (the depth-sorted splats "
      "drawn as quads and blended by the graphics pipeline)",
      [&options](const std::string& text) {
        try {
          options.compositor = parse_compositor(text);
        } catch (const std::invalid_argument&) {
          throw UsageError("--compositor must be sorted, stochastic or raster, got " + single_quoted(text));
        }
      });
  parser.add_value("--max-alpha", "A",
                   "the cap on one splat's alpha at a pixel the splats were trained with: 0.99 (3DGS, the "
                   "default) or 0.999 (gsplat)",
                   [&options](const std::string& text) {
                     const double cap = parse_double("--max-alpha", text);
                     if (!(cap > 0 && cap < 1))
                       throw UsageError("--max-alpha must be between 0 and 1, got " + single_quoted(text));
                     options.max_alpha = cap;
                   });
}

void add_memory_budget_option(ArgParser& parser, uint64_t& budget, const std::string& what_it_adds) {
  parser.add_value(
      "--memory-budget", "SIZE",
      "device memory a frame may hold, e.g. 512M or 2G: a scene whose frame needs more renders in "
      "parts that follow the depth order, into the same image bit for bit (docs/big-scenes.md; " +
          what_it_adds + "default: no budget)",
      [&budget](const std::string& text) { budget = parse_byte_size("--memory-budget", text); });
}

void add_camera_model_options(ArgParser& parser, CameraModelFlags& flags) {
  parser.section("camera model (every frame's camera, its pose and size kept, through another lens)");
  parser.add_value("--fisheye", "DEG",
                   "an equidistant fisheye whose field of view spans DEG degrees across the image's shorter "
                   "side (up to 360: a circular fisheye, past 180 it sees behind)",
                   [&flags](const std::string& text) {
                     const double degrees = parse_double("--fisheye", text);
                     if (!(degrees > 0 && degrees <= 360))
                       throw UsageError("--fisheye must be in (0, 360] degrees, got " + single_quoted(text));
                     flags.fisheye_fov_deg = degrees;
                   });
  parser.add_value(
      "--orthographic", "H", "an orthographic view H world units tall (parallel rays)",
      [&flags](const std::string& text) {
        const double height = parse_double("--orthographic", text);
        if (!(height > 0 && std::isfinite(height)))
          throw UsageError("--orthographic must be a positive number, got " + single_quoted(text));
        flags.view_height = height;
      });
  parser.add_switch(
      "--equirectangular",
      "the 360x180 panorama around the camera (give a 2:1 size, e.g. --width 2048 --height 1024)",
      &flags.equirectangular);
}

void check_camera_model_options(const CameraModelFlags& flags) {
  if (flags.given() > 1)
    throw UsageError("--fisheye, --orthographic and --equirectangular are camera models: one of them");
}

Camera camera_for_frame(const CameraModelFlags& flags, const Camera& camera) {
  if (flags.fisheye_fov_deg) return fisheye_camera(camera, *flags.fisheye_fov_deg);
  if (flags.view_height) return orthographic_camera(camera, *flags.view_height);
  if (flags.equirectangular) return equirectangular_camera(camera);
  return camera;
}

void add_splat_budget_option(ArgParser& parser, CommonOptions& options) {
  parser.add_value("--splat-budget", "N",
                   "a LOD set (lod-meta.json): draw at most N Gaussians a frame, each chunk at the level its "
                   "size on screen calls for, chosen again for every frame's camera; a .rad LOD tree: the cut "
                   "Spark's traversal makes for the camera (docs/big-scenes.md; default: --lod's one level)",
                   [&options](const std::string& text) {
                     const int budget = parse_int("--splat-budget", text, 1, std::numeric_limits<int>::max());
                     options.lod.splat_budget = static_cast<uint64_t>(budget);
                   });
}

void apply_training_options(const CommonOptions& options, RenderSettings& settings) {
  if (options.antialiasing) settings.antialiasing = *options.antialiasing;
  if (options.max_alpha) settings.max_alpha = *options.max_alpha;
  if (options.compositor) settings.compositor = *options.compositor;
}

void check_common_options(const ArgParser& parser, const CommonOptions& options) {
  if (options.scene.empty() && options.scenes.empty())
    throw UsageError("missing the SCENE.ply (or scene file .json) argument (see --help)");
  if (!options.cameras.empty() || !options.cameras_files.empty()) {
    for (const char* orbit_flag : {"--azimuth", "--elevation", "--fov", "--distance"})
      if (parser.seen(orbit_flag))
        throw UsageError(std::string(orbit_flag) +
                         " applies only to the orbit camera and cannot be combined with --cameras");
  } else if (parser.seen("--view") && !any_scene_file(options)) {
    // A scene file may bring cameras of its own: whether it does is known once it is read.
    throw UsageError("--view needs --cameras FILE.json (without it the camera is an orbit)");
  }
}

void print_devices() {
  const auto devices = list_devices();
  if (devices.empty()) throw std::runtime_error("no Vulkan devices found");
  const auto uuids = list_device_uuids();
  for (size_t i = 0; i < devices.size(); ++i)
    std::printf("%zu: %s (uuid %s)\n", i, devices[i].c_str(), i < uuids.size() ? uuids[i].c_str() : "?");
}

bool any_scene_file(const CommonOptions& options) {
  if (!options.scene.empty() && is_scene_description(options.scene)) return true;
  return std::any_of(options.scenes.begin(), options.scenes.end(),
                     [](const std::string& scene) { return is_scene_description(scene); });
}

RendererOptions renderer_options(const CommonOptions& options) {
  RendererOptions renderer;
  renderer.device = options.device;
  renderer.validation = options.validation;
  renderer.timestamps = true;
  return renderer;
}

bool parse_and_handle_info_flags(ArgParser& parser, int argc, const char* const* argv,
                                 const CommonOptions& common) {
  if (parse_and_handle_help(parser, argc, argv)) return true;
  if (common.list_devices) {
    print_devices();
    return true;
  }
  return false;
}

}  // namespace tilesplat::cli
