// tilesplat-info's command line: its options and their declarations.
#pragma once

#include <string>
#include <vector>

#include "cli.h"

namespace tilesplat::info {

inline constexpr const char* kProgram = "tilesplat-info";
inline constexpr const char* kUsage = "tilesplat-info [options] FILE...";
inline constexpr const char* kDescription =
    "Prints what each scene file holds: format and version, Gaussians, SH degree, size, boxes, "
    "opacity and scale ranges, non-finite values, and the time and memory loading it took. Reads "
    ".ply, compressed .ply, .splat, .spz, .sog, SOG meta.json, .ksplat, .rad, .glb and .gltf.";

struct InfoOptions {
  std::vector<std::string> files;
  bool json = false;
  bool strict = false;
};

// Declares every flag of tilesplat-info.
void add_info_options(tilesplat::cli::ArgParser& parser, InfoOptions& options);

// Throws UsageError when no FILE was given.
void check_info_flags(const InfoOptions& options);

}  // namespace tilesplat::info
