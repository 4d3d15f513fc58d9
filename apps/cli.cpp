#include "cli.h"

#include "tilesplat/camera_sets.h"
#include "tilesplat/sort_strategy.h"
#include "tilesplat/version.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <system_error>
#include <utility>

namespace tilesplat::cli {

namespace fs = std::filesystem;

namespace {

constexpr size_t kHelpFlagColumn = 30;  // where the help text of a flag starts
constexpr size_t kHelpWidth = 100;      // wrap help text at this column

std::string single_quoted(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out += '\'';
  out += text;
  out += '\'';
  return out;
}

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return std::string(text.substr(first, last - first + 1));
}

// Appends `text` word-wrapped into [indent, kHelpWidth), the first line continuing at `column`.
void append_wrapped(std::string& out, std::string_view text, size_t column, size_t indent) {
  size_t pos = 0;
  bool first_word = true;
  while (pos < text.size()) {
    const auto end = std::min(text.find(' ', pos), text.size());
    const std::string_view word = text.substr(pos, end - pos);
    pos = end + 1;
    if (word.empty()) continue;
    if (!first_word && column + 1 + word.size() > kHelpWidth) {
      out += '\n';
      out.append(indent, ' ');
      column = indent;
    } else if (!first_word) {
      out += ' ';
      ++column;
    }
    out += word;
    column += word.size();
    first_word = false;
  }
}

std::string join(const std::vector<std::string>& items, std::string_view separator) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) {
    if (i) out += separator;
    out += items[i];
  }
  return out;
}

std::string group_thousands(uint64_t value) {
  std::string digits = std::to_string(value);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

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

// ---------------------------------------------------------------------------------------------
// ArgParser

ArgParser::ArgParser(std::string program, std::string usage, std::string description)
    : program_(std::move(program)), usage_(std::move(usage)), description_(std::move(description)) {
  sections_.push_back("options");
}

void ArgParser::section(std::string title) { sections_.push_back(std::move(title)); }

void ArgParser::add_value(std::string name, std::string value_name, std::string help,
                          std::function<void(const std::string&)> on_value, std::string short_name) {
  Option option;
  option.name = std::move(name);
  option.short_name = std::move(short_name);
  option.value_name = std::move(value_name);
  option.help = std::move(help);
  option.on_value = std::move(on_value);
  option.section = sections_.size() - 1;
  options_.push_back(std::move(option));
}

void ArgParser::add_string(std::string name, std::string value_name, std::string help, std::string* target,
                           std::string short_name) {
  const std::string flag = name;
  add_value(
      std::move(name), std::move(value_name), std::move(help),
      [target, flag](const std::string& text) {
        if (text.empty()) throw UsageError(flag + " expects a value, got an empty string");
        *target = text;
      },
      std::move(short_name));
}

void ArgParser::add_int(std::string name, std::string value_name, std::string help, int* target, int min,
                        int max) {
  const std::string flag = name;
  add_value(std::move(name), std::move(value_name), std::move(help),
            [target, flag, min, max](const std::string& text) { *target = parse_int(flag, text, min, max); });
}

void ArgParser::add_double(std::string name, std::string value_name, std::string help, double* target) {
  const std::string flag = name;
  add_value(std::move(name), std::move(value_name), std::move(help),
            [target, flag](const std::string& text) { *target = parse_double(flag, text); });
}

void ArgParser::add_switch(std::string name, std::string help, bool* target) {
  Option option;
  option.name = std::move(name);
  option.help = std::move(help);
  option.switch_target = target;
  option.section = sections_.size() - 1;
  options_.push_back(std::move(option));
}

void ArgParser::add_positional(std::string value_name, std::string help, std::string* target) {
  positionals_.push_back({std::move(value_name), std::move(help), target, nullptr});
}

void ArgParser::add_positional_list(std::string value_name, std::string help, std::vector<std::string>* target) {
  positionals_.push_back({std::move(value_name) + "...", std::move(help), nullptr, target});
}

const ArgParser::Option* ArgParser::find(std::string_view name) const {
  for (const auto& option : options_)
    if (option.name == name || (!option.short_name.empty() && option.short_name == name)) return &option;
  return nullptr;
}

ArgParser::Outcome ArgParser::parse(int argc, const char* const* argv) {
  // --help wins over any other mistake on the line (whoever asks for help gets it), then --version.
  bool version = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") break;
    if (arg == "-h" || arg == "--help") return Outcome::kHelp;
    version = version || arg == "--version";
  }
  if (version) return Outcome::kVersion;

  size_t next_positional = 0;
  bool flags_ended = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (!flags_ended && arg == "--") {
      flags_ended = true;
      continue;
    }
    if (!flags_ended && arg.size() > 1 && arg[0] == '-') {
      std::string name = arg;
      std::string inline_value;
      bool has_inline_value = false;
      if (arg.rfind("--", 0) == 0) {
        if (const auto eq = arg.find('='); eq != std::string::npos) {
          name = arg.substr(0, eq);
          inline_value = arg.substr(eq + 1);
          has_inline_value = true;
        }
      }
      const Option* option = find(name);
      if (!option) throw UsageError("unknown flag " + single_quoted(name) + " (see --help)");
      if (option->switch_target) {
        if (has_inline_value) throw UsageError(option->name + " takes no value");
        *option->switch_target = true;
      } else {
        std::string value;
        if (has_inline_value) {
          value = inline_value;
        } else if (i + 1 < argc) {
          // The next argument is the value even when it starts with '-' ("--azimuth -30").
          value = argv[++i];
        } else {
          throw UsageError(name + " expects a value (" + option->value_name + ")");
        }
        option->on_value(value);
      }
      seen_.insert(option->name);
      continue;
    }
    if (next_positional >= positionals_.size())
      throw UsageError("unexpected argument " + single_quoted(arg) + " (see --help)");
    if (auto* list = positionals_[next_positional].list_target)
      list->push_back(arg);  // a list takes the rest, so next_positional stays on it
    else
      *positionals_[next_positional++].target = arg;
  }
  return Outcome::kRun;
}

std::string ArgParser::help_text() const {
  std::string out = "usage: " + usage_ + "\n\n";
  append_wrapped(out, description_, 0, 0);
  out += "\n";

  auto append_entry = [&out](const std::string& left, const std::string& help) {
    out += left;
    size_t column = left.size();
    if (column + 1 >= kHelpFlagColumn) {
      out += '\n';
      column = 0;
    }
    out.append(kHelpFlagColumn - column, ' ');
    append_wrapped(out, help, kHelpFlagColumn, kHelpFlagColumn);
    out += '\n';
  };

  if (!positionals_.empty()) {
    out += "\narguments:\n";
    for (const auto& positional : positionals_) append_entry("  " + positional.value_name, positional.help);
  }
  for (size_t section = 0; section < sections_.size(); ++section) {
    const bool has_entries = std::any_of(options_.begin(), options_.end(),
                                         [section](const Option& option) { return option.section == section; });
    if (!has_entries && section != 0) continue;
    out += "\n" + sections_[section] + ":\n";
    if (section == 0) {
      append_entry("  -h, --help", "print this help and exit");
      append_entry("      --version",
                   "print the version of tilesplat (with its commit and build type) and exit");
    }
    for (const auto& option : options_) {
      if (option.section != section) continue;
      std::string left = "  ";
      left += option.short_name.empty() ? "    " : option.short_name + ", ";
      left += option.name;
      if (!option.value_name.empty()) left += " " + option.value_name;
      append_entry(left, option.help);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Value parsers

int parse_int(std::string_view flag, std::string_view text, int min, int max) {
  const std::string expectation = min >= 1   ? "a positive integer"
                                  : min == 0 ? "a non-negative integer"
                                             : "an integer";
  const std::string got = ", got " + single_quoted(text);
  long long value = 0;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(first, last, value);
  if (text.empty() || error == std::errc::invalid_argument || end != last)
    throw UsageError(std::string(flag) + " expects " + expectation + got);
  if (error == std::errc::result_out_of_range || value > max) {
    if (error == std::errc::result_out_of_range && text.front() == '-')
      throw UsageError(std::string(flag) + " expects " + expectation + got);
    throw UsageError(std::string(flag) + " must be at most " + std::to_string(max) + got);
  }
  if (value < min) {
    if (min == 0 || min == 1) throw UsageError(std::string(flag) + " expects " + expectation + got);
    throw UsageError(std::string(flag) + " must be at least " + std::to_string(min) + got);
  }
  return static_cast<int>(value);
}

double parse_double(std::string_view flag, std::string_view text) {
  const std::string trimmed = trim(text);
  double value = 0;
  const char* first = trimmed.data();
  const char* last = trimmed.data() + trimmed.size();
  const auto [end, error] = std::from_chars(first, last, value);
  if (trimmed.empty() || error != std::errc() || end != last)
    throw UsageError(std::string(flag) + " expects a number, got " + single_quoted(text));
  if (!std::isfinite(value))
    throw UsageError(std::string(flag) + " expects a finite number, got " + single_quoted(text));
  return value;
}

std::array<float, 3> parse_rgb(std::string_view flag, std::string_view text) {
  const auto parts = split(text, ',');
  const std::string expectation =
      std::string(flag) + " expects three numbers r,g,b (e.g. 0.5,0.5,0.5), got " + single_quoted(text);
  if (parts.size() != 3) throw UsageError(expectation);
  std::array<float, 3> rgb{};
  for (size_t c = 0; c < 3; ++c) {
    const std::string part = trim(parts[c]);
    double value = 0;
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (part.empty() || error != std::errc() || end != part.data() + part.size())
      throw UsageError(expectation);
    if (!std::isfinite(value) || std::fabs(value) > double(std::numeric_limits<float>::max()))
      throw UsageError(std::string(flag) + " expects finite numbers, got " + single_quoted(part) + " in " +
                       single_quoted(text));
    rgb[c] = static_cast<float>(value);
  }
  return rgb;
}

std::vector<ImageSize> parse_resolutions(std::string_view flag, std::string_view text) {
  std::vector<ImageSize> sizes;
  for (const auto& part : split(text, ',')) {
    const std::string entry = trim(part);
    auto fail = [&] {
      throw UsageError(std::string(flag) + " expects WxH sizes from 1x1 to " +
                       format_size(kMaxImageSide, kMaxImageSide) +
                       ", comma-separated (e.g. 1920x1080,1280x720), got " + single_quoted(entry) +
                       (entry == text ? "" : " in " + single_quoted(text)));
    };
    const auto x = entry.find('x');
    if (x == std::string::npos) fail();
    int side[2] = {0, 0};
    const std::string_view halves[2] = {std::string_view(entry).substr(0, x), std::string_view(entry).substr(x + 1)};
    for (int i = 0; i < 2; ++i) {
      // The whole half must be the number: "2x3" after the first 'x' of "1x2x3" is not.
      const auto [end, error] = std::from_chars(halves[i].data(), halves[i].data() + halves[i].size(), side[i]);
      if (halves[i].empty() || error != std::errc() || end != halves[i].data() + halves[i].size() || side[i] < 1 ||
          side[i] > kMaxImageSide)
        fail();
    }
    const ImageSize size{side[0], side[1]};
    if (std::find(sizes.begin(), sizes.end(), size) == sizes.end()) sizes.push_back(size);
  }
  return sizes;
}

std::string format_size(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

std::vector<std::string> split(std::string_view text, char separator) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const auto end = text.find(separator, start);
    if (end == std::string_view::npos) {
      parts.emplace_back(text.substr(start));
      return parts;
    }
    parts.emplace_back(text.substr(start, end - start));
    start = end + 1;
  }
}

// ---------------------------------------------------------------------------------------------
// Common options

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
    parser.add_positional("SCENE.ply",
                          "the scene: a 3D Gaussian Splatting file (.ply, .compressed.ply, .splat, .spz, .sog, SOG meta.json, "
                          ".glb, .gltf; docs/formats.md), or a scene file "
                          "(.json, docs/scene-format.md) that places several of them and brings cameras, "
                          "background and outputs",
                          &options.scene);
  } else {
    parser.add_positional_list("SCENE.ply",
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
  parser.add_value("--view", "N", "which view of --cameras (or of a scene file's cameras), counting from 0 (default 0)",
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
  parser.add_value("--azimuth", "DEG",
                   "orbit camera: angle around the scene (default " + format_fixed(orbit_defaults.azimuth_deg, 0) +
                       ")",
                   [&options](const std::string& text) {
                     options.orbit.azimuth_deg = parse_double("--azimuth", text);
                     options.orbit_given = true;
                   });
  parser.add_value("--elevation", "DEG",
                   "orbit camera: angle above the horizon, between -90 and 90 (default " +
                       format_fixed(orbit_defaults.elevation_deg, 0) + ")",
                   [&options](const std::string& text) {
                     const double degrees = parse_double("--elevation", text);
                     if (!(degrees > -90 && degrees < 90))
                       throw UsageError("--elevation must be strictly between -90 and 90, got " + single_quoted(text));
                     options.orbit.elevation_deg = degrees;
                     options.orbit_given = true;
                   });
  parser.add_value("--fov", "DEG",
                   "orbit camera: vertical field of view (default " +
                       format_fixed(orbit_defaults.vertical_fov_deg, 0) + ")",
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
                     if (!(scale > 0)) throw UsageError("--distance must be positive, got " + single_quoted(text));
                     options.orbit.distance_scale = scale;
                     options.orbit_given = true;
                   });

  parser.section("scene and device");
  parser.add_switch("--strict",
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
  parser.add_switch("--validation",
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
    parser.add_value("--sort", "NAME[,NAME...]",
                     "key sort strategies to measure, comma-separated, or 'all' (every one but auto): " +
                         join(available, ", ") + " (default all)",
                     [&options, available, strategies](const std::string& text) {
                       options.sorts.clear();
                       for (const auto& part : split(text, ',')) {
                         if (trim(part) == "all") {
                           for (const auto& name : strategies)
                             if (std::find(options.sorts.begin(), options.sorts.end(), name) ==
                                 options.sorts.end())
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
      "reference, depth24, depth16, opacity-extent, square-tiles, sh0..sh3, fp16-sh, fp16-cov, t-cutoff=X, "
      "alpha-cutoff=X (X a number or 1/64), resortN (2-16); combine with '+'";
  auto parse_modes = [](const std::string& text) {
    try {
      return parse_accuracy_modes(std::string(trim(text)));
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--mode: ") + e.what());
    }
  };
  if (sort_choice == SortChoice::kOne) {
    parser.add_value("--mode", "MODES", "accuracy modes (default reference): " + modes_help,
                     [&options, parse_modes](const std::string& text) { options.modes = {parse_modes(text)}; });
  } else {
    parser.add_value("--mode", "MODES[,MODES...]",
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
  parser.add_value("--antialiasing", "MODE",
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

LoadedScene load_scene_file(const fs::path& path, bool strict, std::string_view program) {
  LoadedScene loaded;
  loaded.path = path;
  require_input_file(loaded.path, "scene");

  const auto start = std::chrono::steady_clock::now();
  LoadOptions load_options;
  load_options.strict = strict;
  try {
    if (is_scene_description(loaded.path)) {
      loaded.description = load_scene_description(loaded.path);
      loaded.scene = load_described_scene(*loaded.description, load_options, &loaded.report);
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
  return out;
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
    settings.accuracy.sh_degree_cap = std::min(settings.accuracy.sh_degree_cap, *description.effects.sh_degree);
}

bool any_scene_file(const CommonOptions& options) {
  if (!options.scene.empty() && is_scene_description(options.scene)) return true;
  return std::any_of(options.scenes.begin(), options.scenes.end(),
                     [](const std::string& scene) { return is_scene_description(scene); });
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

NamedCamera view_camera(const std::vector<CameraView>& views, int index, const fs::path& cameras_path, int width,
                        int height, std::string_view flag) {
  if (index < 0 || static_cast<size_t>(index) >= views.size())
    throw UsageError(std::string(flag) + " " + std::to_string(index) + " is out of range: " +
                     single_quoted(cameras_path.string()) + " has " + std::to_string(views.size()) + " views (0.." +
                     std::to_string(views.size() - 1) + ")");
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
  if (loaded.scene.empty())
    throw std::runtime_error(single_quoted(loaded.path.string()) +
                             " has no Gaussians for the orbit camera to frame; pass --cameras FILE.json");
  const ImageSize size = orbit_image_size(width, height);
  NamedCamera named;
  named.camera = orbit_camera(loaded.scene, size.width, size.height, orbit);
  named.description = "orbit azimuth " + format_fixed(orbit.azimuth_deg, 1) + " elevation " +
                      format_fixed(orbit.elevation_deg, 1) + " fov " + format_fixed(orbit.vertical_fov_deg, 1);
  check_camera_size(named.camera);
  return named;
}

SceneViews camera_views(const CommonOptions& options, const LoadedScene& loaded) {
  if (options.cameras.empty()) return scene_views(loaded);
  return {load_camera_views(options.cameras), options.cameras};
}

LoadedScene load_scene_and_camera(const CommonOptions& options, std::string_view program) {
  LoadedScene loaded = load_scene_file(options.scene, options.strict, program);
  const SceneViews cameras = camera_views(options, loaded);
  NamedCamera named;
  if (!cameras.views.empty()) {
    if (options.cameras.empty() && options.orbit_given)
      throw UsageError("--azimuth, --elevation, --fov and --distance apply only to the orbit camera, and " +
                       single_quoted(loaded.path.string()) + " has cameras of its own (pick one with --view)");
    named = view_camera(cameras.views, options.view, cameras.file, options.width, options.height);
    loaded.view_index = options.view;
    loaded.view_name = cameras.views[size_t(options.view)].name;  // in range: view_camera checked it
  } else {
    if (options.view_given)
      throw UsageError("--view needs cameras: " + single_quoted(loaded.path.string()) +
                       " has none, and no --cameras FILE.json was given (without them the camera is an orbit)");
    named = orbit_view(loaded, options.width, options.height, options.orbit);
  }
  loaded.camera = named.camera;
  loaded.camera_description = named.description;
  return loaded;
}

RendererOptions renderer_options(const CommonOptions& options) {
  RendererOptions renderer;
  renderer.device = options.device;
  renderer.validation = options.validation;
  renderer.timestamps = true;
  return renderer;
}

std::string describe_scene(const GaussianScene& scene) {
  return group_thousands(scene.size()) + " Gaussians (SH" + std::to_string(scene.sh_degree) + ")";
}

// ---------------------------------------------------------------------------------------------
// Errors

std::string one_line(std::string_view message) {
  std::string out;
  out.reserve(message.size());
  bool pending_break = false;
  for (const char c : message) {
    if (c == '\n' || c == '\r') {
      pending_break = !out.empty();
      continue;
    }
    if (pending_break) {
      out += "; ";
      pending_break = false;
    }
    out += c;
  }
  return out;
}

void print_error(std::string_view program, std::string_view message) {
  std::fflush(stdout);
  const std::string line = std::string(program) + ": error: " + one_line(message) + "\n";
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
}

void print_warning(std::string_view program, std::string_view message) {
  const std::string line = std::string(program) + ": warning: " + one_line(message) + "\n";
  std::fputs(line.c_str(), stderr);
}

int run_app(std::string_view program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const UsageError& error) {
    print_error(program, error.what());
    return kExitUsage;
  } catch (const std::bad_alloc&) {
    print_error(program, "out of memory");
    return kExitFailure;
  } catch (const std::exception& error) {
    print_error(program, error.what());
    return kExitFailure;
  } catch (...) {
    print_error(program, "unexpected error");
    return kExitFailure;
  }
}

// ---------------------------------------------------------------------------------------------
// Files

bool has_extension(const fs::path& path, std::string_view extension) {
  const std::string actual = path.extension().string();
  return actual.size() == extension.size() &&
         std::equal(actual.begin(), actual.end(), extension.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
         });
}

void check_output_path(const fs::path& path, std::string_view flag) {
  if (path.empty()) throw UsageError(std::string(flag) + " expects a file name");
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) +
                             "): it is a directory");
  fs::path directory = path.parent_path();
  if (directory.empty()) directory = ".";
  const auto status = fs::status(directory, ec);
  if (!fs::exists(status))
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) +
                             "): directory " + single_quoted(directory.string()) + " does not exist");
  if (!fs::is_directory(status))
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) + "): " +
                             single_quoted(directory.string()) + " is not a directory");
  if (::access(directory.c_str(), W_OK) != 0)
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) +
                             "): directory " + single_quoted(directory.string()) + " is not writable");
}

void check_distinct_paths(const std::vector<std::pair<std::string, fs::path>>& paths) {
  std::vector<std::pair<std::string, fs::path>> resolved;
  for (const auto& [flag, path] : paths) {
    if (path.empty()) continue;
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(path, ec);
    if (ec) canonical = fs::absolute(path, ec).lexically_normal();
    for (const auto& [other_flag, other] : resolved)
      if (other == canonical)
        throw UsageError(other_flag + " and " + flag + " name the same file " + single_quoted(path.string()));
    resolved.emplace_back(flag, canonical);
  }
}

// ---------------------------------------------------------------------------------------------
// Formatting

std::string format_fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string format_number(double value, int decimals) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (std::isnan(value)) return "nan";
  return format_fixed(value, decimals);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) != 0; }

std::string version_text(std::string_view program) {
  const BuildInfo build = build_info();
  std::string text = std::string(program) + " " + build.version;
  std::string details;
  if (*build.git_commit) details = std::string("commit ") + build.git_commit;
  if (*build.build_type) details += (details.empty() ? "" : ", ") + std::string(build.build_type);
  return details.empty() ? text : text + " (" + details + ")";
}

std::string command_line(std::string_view program, int argc, const char* const* argv) {
  std::string command(program);
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    command += ' ';
    if (!argument.empty() && argument.find_first_of(" \t\n'\"\\$`;&|<>()*?") == std::string_view::npos) {
      command += argument;
      continue;
    }
    command += '\'';
    for (const char c : argument) {
      if (c == '\'')
        command += "'\\''";
      else
        command += c;
    }
    command += '\'';
  }
  return command;
}

std::string with_provenance_columns(const std::string& csv, const std::string& command) {
  const BuildInfo build = build_info();
  const std::string header = ",tilesplat_version,tilesplat_commit,build_type,command";
  const std::string values = "," + csv_field(build.version) + "," + csv_field(build.git_commit) + "," +
                             csv_field(build.build_type) + "," + csv_field(command);
  std::string out;
  out.reserve(csv.size() + 64 * size_t(std::count(csv.begin(), csv.end(), '\n')));
  bool quoted = false, first_record = true;
  for (size_t i = 0; i < csv.size(); ++i) {
    const char c = csv[i];
    if (c == '"') quoted = !quoted;  // a doubled quote inside a field toggles twice
    if (c == '\n' && !quoted) {
      const bool crlf = !out.empty() && out.back() == '\r';
      if (crlf) out.pop_back();
      out += first_record ? header : values;
      if (crlf) out += '\r';
      first_record = false;
    }
    out += c;
  }
  if (!csv.empty() && csv.back() != '\n')
    out += first_record ? header : values;  // a last record without '\n'
  return out;
}

bool parse_and_handle_help(ArgParser& parser, int argc, const char* const* argv) {
  switch (parser.parse(argc, argv)) {
    case ArgParser::Outcome::kHelp:
      std::fputs(parser.help_text().c_str(), stdout);
      return true;
    case ArgParser::Outcome::kVersion:
      std::puts(version_text(parser.program()).c_str());
      return true;
    case ArgParser::Outcome::kRun:
      break;
  }
  return false;
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

namespace {

uint64_t proc_status_kib(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  const std::string prefix = std::string(field) + ":";
  while (std::getline(status, line))
    if (line.starts_with(prefix)) return std::strtoull(line.c_str() + prefix.size(), nullptr, 10);
  return 0;
}

}  // namespace

void reset_peak_memory() {
#if defined(__GLIBC__)
  // Heap memory freed by earlier work goes back to the system first: otherwise the next step could
  // reuse it without the resident size growing, and its peak would read low.
  malloc_trim(0);
#endif
  std::ofstream("/proc/self/clear_refs") << "5";
}
uint64_t peak_memory_bytes() { return proc_status_kib("VmHWM") * 1024; }
uint64_t resident_memory_bytes() { return proc_status_kib("VmRSS") * 1024; }

}  // namespace tilesplat::cli
