// Running the apps as processes, for the tests of their command lines: exit code, stdout and stderr,
// and the checks every app's failures share.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace tilesplat::testing {

struct ProcessResult {
  int exit_code = -1;  // -1 when the process did not exit normally (a signal, a crash)
  std::string out;
  std::string err;
};

// Runs `prefix exe args...` through the shell (prefix: e.g. "env -u DISPLAY " or "xvfb-run -a ";
// empty for none) with stdout captured and stderr in a file beside the test's temporaries.
// VK_LOADER_DEBUG is emptied so that loader chatter cannot pollute stderr. A validation-layer message
// in stderr (the apps print them and still exit 0) fails the calling test.
ProcessResult run_process(const std::string& prefix, const std::string& exe, const std::vector<std::string>& args);

// How a test gives the viewer a display: "" for the session's own (DISPLAY or WAYLAND_DISPLAY), else the
// prefix of a private Xvfb server (each test process starts its search for a free server number at its
// own, so parallel tests do not race for one); none when neither exists (then kNoDisplay says why).
std::optional<std::string> display_prefix();
inline constexpr const char* kNoDisplay =
    "no display for the viewer's window: DISPLAY and WAYLAND_DISPLAY are unset and xvfb-run is not installed "
    "(Debian: xvfb xauth)";

std::string read_file(const std::filesystem::path& path);

// An empty directory for a test's outputs (temporaries persist between runs, so start clean).
std::filesystem::path fresh_output_dir();

// The names in a directory, sorted.
std::vector<std::string> entries(const std::filesystem::path& dir);

size_t line_count(const std::string& text);

// Every failure is exactly one line: "PROGRAM: error: ...".
void expect_one_error_line(const ProcessResult& result, const std::string& program);

}  // namespace tilesplat::testing
