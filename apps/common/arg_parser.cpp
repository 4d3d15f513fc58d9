#include "arg_parser.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>

#include "text.h"
#include "tilesplat/version.h"

namespace tilesplat::cli {

namespace {

constexpr size_t kHelpFlagColumn = 30;  // where the help text of a flag starts
constexpr size_t kHelpWidth = 100;      // wrap help text at this column

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

// "  -o, --output FILE.exr      help..." with the help wrapped at kHelpWidth.
void append_entry(std::string& out, const std::string& left, const std::string& help) {
  out += left;
  size_t column = left.size();
  if (column + 1 >= kHelpFlagColumn) {
    out += '\n';
    column = 0;
  }
  out.append(kHelpFlagColumn - column, ' ');
  append_wrapped(out, help, kHelpFlagColumn, kHelpFlagColumn);
  out += '\n';
}

// --help in the apps' layout: the usage line, the description, the positional arguments, then the
// flags under their sections, each section in the order of its first flag. Everything listed comes
// from the declarations of the CLI::App.
class HelpFormatter : public CLI::FormatterBase {
 public:
  explicit HelpFormatter(std::string usage) : usage_(std::move(usage)) {}

  std::string make_help(const CLI::App* app, std::string, CLI::AppFormatMode) const override {
    std::string out = "usage: " + usage_ + "\n\n";
    append_wrapped(out, app->get_description(), 0, 0);
    out += "\n";
    const auto positionals =
        app->get_options([](const CLI::Option* option) { return option->get_positional(); });
    if (!positionals.empty()) {
      out += "\narguments:\n";
      for (const CLI::Option* positional : positionals)
        append_entry(out, "  " + positional->get_name(true), positional->get_description());
    }
    for (const std::string& group : app->get_groups()) {
      const auto flags = app->get_options([&group](const CLI::Option* option) {
        return option->nonpositional() && option->get_group() == group;
      });
      if (flags.empty()) continue;
      out += "\n" + group + ":\n";
      for (const CLI::Option* flag : flags) {
        std::string left = "  ";
        left += flag->get_snames().empty() ? "    " : "-" + flag->get_snames().front() + ", ";
        left += "--" + flag->get_lnames().front();
        if (!flag->get_type_name().empty()) left += " " + flag->get_type_name();
        append_entry(out, left, flag->get_description());
      }
    }
    return out;
  }

 private:
  std::string usage_;
};

// The flag a CLI11 message is about: its first word ("--width: 1 required W missing",
// "--strict was given a disallowed flag override").
std::string flag_of_message(const std::string& message) {
  return message.substr(0, message.find_first_of(": "));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ArgParser

ArgParser::ArgParser(std::string program, std::string usage, std::string description)
    : program_(std::move(program)), app_(std::make_unique<CLI::App>(std::move(description), program_)) {
  app_->formatter(std::make_shared<HelpFormatter>(std::move(usage)));
  // --help and --version are found before CLI11 parses (whoever asks for help gets it, whatever else
  // is wrong on the line); they are declared here so that --help lists them.
  app_->set_help_flag();
  const std::string help = "print this help and exit";
  const std::string version = "print the version of tilesplat (with its commit and build type) and exit";
  app_->add_flag("-h,--help", help)->group(section_);
  app_->add_flag("--version", version)->group(section_);
  // Arguments CLI11 does not know are kept, and reported after parsing in the apps' words.
  app_->allow_extras();
}

ArgParser::~ArgParser() = default;

void ArgParser::section(std::string title) {
  section_ = std::move(title);
}

void ArgParser::add_value(std::string name, std::string value_name, std::string help,
                          std::function<void(const std::string&)> on_value, std::string short_name) {
  const std::string names = short_name.empty() ? name : short_name + "," + name;
  app_->add_option_function<std::string>(names, std::move(on_value), std::move(help))
      ->type_name(std::move(value_name))
      ->group(section_)
      ->trigger_on_parse();  // in command-line order, once per occurrence
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
  app_->add_flag_callback(
          name, [target] { *target = true; }, std::move(help))
      ->group(section_)
      ->disable_flag_override();  // "--strict=false" is a mistake, not a way to say no
}

void ArgParser::add_positional(std::string value_name, std::string help, std::string* target) {
  app_->add_option(std::move(value_name), *target, std::move(help));
}

void ArgParser::add_positional_list(std::string value_name, std::string help,
                                    std::vector<std::string>* target) {
  app_->add_option(std::move(value_name) + "...", *target, std::move(help));
}

bool ArgParser::seen(std::string_view name) const {
  const CLI::Option* option = app_->get_option_no_throw(std::string(name));
  return option && option->count() > 0;
}

ArgParser::Outcome ArgParser::parse(int argc, const char* const* argv) {
  bool version = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") break;
    if (arg == "-h" || arg == "--help") return Outcome::kHelp;
    version = version || arg == "--version";
  }
  if (version) return Outcome::kVersion;

  try {
    app_->parse(argc, argv);
  } catch (const CLI::ArgumentMismatch& error) {
    // A value flag at the end of the line, or a switch given a value.
    std::string flag = flag_of_message(error.what());
    const CLI::Option* option = app_->get_option_no_throw(flag);
    if (!option && !flag.starts_with("-")) {  // some messages name the flag without its dashes
      flag = (flag.size() == 1 ? "-" : "--") + flag;
      option = app_->get_option_no_throw(flag);
    }
    if (option && option->get_type_name().empty()) throw UsageError(flag + " takes no value");
    throw UsageError(flag + " expects a value" +
                     (option ? " (" + option->get_type_name() + ")" : std::string()));
  } catch (const CLI::ParseError& error) {
    throw UsageError(one_line(error.what()) + " (see --help)");
  }
  const std::vector<std::string> unknown = app_->remaining();
  if (!unknown.empty()) {
    const std::string& first = unknown.front();
    if (first.size() > 1 && first[0] == '-')
      throw UsageError("unknown flag " + single_quoted(first.substr(0, first.find('='))) + " (see --help)");
    throw UsageError("unexpected argument " + single_quoted(first) + " (see --help)");
  }
  return Outcome::kRun;
}

std::string ArgParser::help_text() const {
  return app_->help();
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

std::string version_text(std::string_view program) {
  const BuildInfo build = build_info();
  std::string text = std::string(program) + " " + build.version;
  std::string details;
  if (*build.git_commit) details = std::string("commit ") + build.git_commit;
  if (*build.build_type) details += (details.empty() ? "" : ", ") + std::string(build.build_type);
  return details.empty() ? text : text + " (" + details + ")";
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

uint64_t parse_byte_size(std::string_view flag, std::string_view text) {
  const std::string trimmed = trim(text);
  const std::string expectation =
      std::string(flag) + " expects a size in bytes (512M, 1.5G, 8GiB, 1048576), got " + single_quoted(text);
  double value = 0;
  const auto [end, error] = std::from_chars(trimmed.data(), trimmed.data() + trimmed.size(), value);
  if (trimmed.empty() || error != std::errc()) throw UsageError(expectation);
  std::string unit(end, trimmed.data() + trimmed.size());
  if (unit.ends_with("iB")) unit.resize(unit.size() - 2);
  const std::string units = "KMGT";
  double scale = 1;
  if (unit.size() == 1 && units.find(unit[0]) != std::string::npos)
    scale = std::ldexp(1.0, 10 * int(units.find(unit[0]) + 1));
  else if (!unit.empty() && unit != "B")
    throw UsageError(expectation);
  const double bytes = value * scale;
  if (!std::isfinite(bytes) || bytes < 1 || bytes > 0x1p63)
    throw UsageError(std::string(flag) + " must be a positive size below 8 EiB, got " + single_quoted(text));
  return uint64_t(bytes);
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
    const std::string_view halves[2] = {std::string_view(entry).substr(0, x),
                                        std::string_view(entry).substr(x + 1)};
    for (int i = 0; i < 2; ++i) {
      // The whole half must be the number: "2x3" after the first 'x' of "1x2x3" is not.
      const auto [end, error] =
          std::from_chars(halves[i].data(), halves[i].data() + halves[i].size(), side[i]);
      if (halves[i].empty() || error != std::errc() || end != halves[i].data() + halves[i].size() ||
          side[i] < 1 || side[i] > kMaxImageSide)
        fail();
    }
    const ImageSize size{side[0], side[1]};
    if (std::find(sizes.begin(), sizes.end(), size) == sizes.end()) sizes.push_back(size);
  }
  return sizes;
}

std::string format_size(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace tilesplat::cli
