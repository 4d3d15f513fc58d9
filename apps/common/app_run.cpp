#include "app_run.h"

#include <unistd.h>

#include <cstdio>
#include <new>
#include <string>

#include "arg_parser.h"
#include "text.h"

namespace tilesplat::cli {

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

void print_saturation_warning(std::string_view program, const std::filesystem::path& exr,
                              const tilesplat::SaturatedValues& saturated, bool half) {
  if (saturated.total() == 0) return;
  print_warning(program, exr.string() + ": " + saturated.describe() + " past the range of " +
                             (half ? "half" : "float") +
                             " stored as its largest finite value (the header's " +
                             tilesplat::kSaturatedAttribute + " records them)");
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

bool stderr_is_terminal() {
  return ::isatty(STDERR_FILENO) != 0;
}

}  // namespace tilesplat::cli
