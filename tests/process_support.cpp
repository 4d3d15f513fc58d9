#include "process_support.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include "test_support.h"

namespace tilesplat::testing {

namespace fs = std::filesystem;

namespace {

std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) {
    if (c == '\'')
      quoted += "'\\''";
    else
      quoted += c;
  }
  return quoted + "'";
}

bool env_set(const char* name) {
  const char* value = std::getenv(name);
  return value && *value;
}

}  // namespace

std::optional<std::string> display_prefix() {
  if (env_set("DISPLAY") || env_set("WAYLAND_DISPLAY")) return "";
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0) return std::nullopt;
  return "xvfb-run -n " + std::to_string(100 + ::getpid() % 800) + " -a ";
}

ProcessResult run_process(const std::string& prefix, const std::string& exe, const std::vector<std::string>& args) {
  static int invocation = 0;
  std::string err_name = "stderr_";
  err_name += std::to_string(invocation++);
  err_name += ".txt";
  const fs::path err_path = temp_dir() / err_name;
  std::string command = "VK_LOADER_DEBUG= ";
  command += prefix;
  command += shell_quote(exe);
  for (const auto& arg : args) {
    command += ' ';
    command += shell_quote(arg);
  }
  command += " 2>";
  command += shell_quote(err_path.string());
  command += " </dev/null";

  ProcessResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) {
    result.err = "popen failed for: " + command;
    return result;
  }
  char buffer[4096];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.out.append(buffer, n);
  const int status = ::pclose(pipe);
  if (status != -1 && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  result.err = read_file(err_path);
  // The apps run with the validation layer on in the tests (TILESPLAT_VALIDATION=1), warn about its
  // messages and still exit 0: every run of an app is checked here, so that no test can miss them.
  for (const char* sign : {"vulkan validation", "Vulkan validation messages"})
    if (result.err.find(sign) != std::string::npos)
      ADD_FAILURE() << "the validation layer reported messages while running " << command << ":\n"
                    << result.err;
  return result;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path fresh_output_dir() {
  const fs::path dir = temp_dir() / "out";
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

size_t line_count(const std::string& text) { return static_cast<size_t>(std::count(text.begin(), text.end(), '\n')); }

void expect_one_error_line(const ProcessResult& result, const std::string& program) {
  EXPECT_EQ(result.err.rfind(program + ": error: ", 0), 0u) << result.err;
  EXPECT_EQ(line_count(result.err), 1u) << result.err;
}

}  // namespace tilesplat::testing
