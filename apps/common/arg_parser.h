// The apps' command lines: CLI11 parses them, from flags declared with their help text, so that
// --help lists exactly what the parser accepts. What is ours is the wording: every mistake is one
// line naming the flag and the text ("--width expects a positive integer, got 'abc'"), and the
// exit codes below.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
}

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

// Flags are declared with their help text (a CLI::App underneath). Value flags take "--flag value" or
// "--flag=value", and the next argument is the value even when it starts with '-' ("--azimuth -30");
// "--" ends the flags. A value's callback runs when the flag is read, in command-line order, once per
// occurrence (a repeated flag such as --cameras sees each of its values).
class ArgParser {
 public:
  enum class Outcome { kRun, kHelp, kVersion };

  ArgParser(std::string program, std::string usage, std::string description);
  ~ArgParser();
  ArgParser(const ArgParser&) = delete;
  ArgParser& operator=(const ArgParser&) = delete;

  // Flags declared after this call are listed under `title` in --help.
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
  // Positional arguments fill their targets in declaration order.
  void add_positional(std::string value_name, std::string help, std::string* target);
  // Takes every positional argument left over (declare it last); shown as "VALUE_NAME..." in --help.
  void add_positional_list(std::string value_name, std::string help, std::vector<std::string>* target);

  // Throws UsageError. Returns kHelp (without parsing anything else) when -h/--help is given, else
  // kVersion when --version is.
  Outcome parse(int argc, const char* const* argv);

  // Whether the flag (its long name) appeared on the command line.
  bool seen(std::string_view name) const;

  std::string help_text() const;
  const std::string& program() const { return program_; }

 private:
  std::string program_;
  std::string section_ = "options";
  std::unique_ptr<CLI::App> app_;
};

// Parses the command line and handles --help and --version, which end the program before it does
// any work. Returns true when the program should exit with kExitOk.
bool parse_and_handle_help(ArgParser& parser, int argc, const char* const* argv);

// "tilesplat-render 0.3.0 (commit 1a2b3c..., Release)": the library's version and build.
std::string version_text(std::string_view program);

// Value parsers shared by the flags; all throw UsageError naming the flag and the text.
// "--width expects a positive integer, got 'abc'"; "--width must be at most 65536, got '70000'".
int parse_int(std::string_view flag, std::string_view text, int min, int max);
double parse_double(std::string_view flag, std::string_view text);
// "r,g,b": three finite floats.
std::array<float, 3> parse_rgb(std::string_view flag, std::string_view text);
// A positive size in bytes: a number with an optional binary unit, K, M, G or T (KiB, MiB, GiB, TiB
// too): "512M", "1.5G", "8GiB", "1048576".
uint64_t parse_byte_size(std::string_view flag, std::string_view text);

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

}  // namespace tilesplat::cli
