// What the apps' outputs record about how they were made: the command line and the build.
#pragma once

#include <string>
#include <string_view>

namespace tilesplat::cli {

// The command as typed ("tilesplat-bench a.ply --csv c.csv"), for the outputs that record how they
// were made. Arguments with spaces or quotes are single-quoted so that a shell runs it again.
std::string command_line(std::string_view program, int argc, const char* const* argv);

// A CSV table with four provenance columns appended to every record: tilesplat_version,
// tilesplat_commit, build_type (build_info()) and command. Every row carries them, so the rows of
// runs concatenated into one table still say which build and command produced each.
std::string with_provenance_columns(const std::string& csv, const std::string& command);

}  // namespace tilesplat::cli
