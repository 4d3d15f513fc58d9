// How an app ends: one line "PROGRAM: error: MESSAGE" on stderr and the exit codes of arg_parser.h.
#pragma once

#include <filesystem>
#include <functional>
#include <string_view>

#include "tilesplat/image.h"

namespace tilesplat::cli {

// Runs an app's body, turning exceptions into one error line and the exit codes (kExitUsage for a
// UsageError, kExitFailure for anything else).
int run_app(std::string_view program, const std::function<int()>& body);
void print_error(std::string_view program, std::string_view message);
void print_warning(std::string_view program, std::string_view message);
bool stderr_is_terminal();
// The one warning line for an EXR in which values saturated (write_exr's SaturatedValues; nothing when none
// did): how many, in which channels, past which type, and that the header records them.
void print_saturation_warning(std::string_view program, const std::filesystem::path& exr,
                              const tilesplat::SaturatedValues& saturated, bool half);

}  // namespace tilesplat::cli
