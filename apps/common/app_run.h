// How an app ends: one line "PROGRAM: error: MESSAGE" on stderr and the exit codes of arg_parser.h.
#pragma once

#include <functional>
#include <string_view>

namespace tilesplat::cli {

// Runs an app's body, turning exceptions into one error line and the exit codes (kExitUsage for a
// UsageError, kExitFailure for anything else).
int run_app(std::string_view program, const std::function<int()>& body);
void print_error(std::string_view program, std::string_view message);
void print_warning(std::string_view program, std::string_view message);
bool stderr_is_terminal();

}  // namespace tilesplat::cli
