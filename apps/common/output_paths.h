// Checks on output paths before any work is done, so that a run that cannot write its result fails
// at once. The files themselves are written with tilesplat::write_file_atomically (tilesplat/image.h).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tilesplat::cli {

// Fails early (std::runtime_error) when `path` cannot be an output: its directory does not
// exist, or it names a directory. `flag` names the option in the message.
void check_output_path(const std::filesystem::path& path, std::string_view flag);
// Throws UsageError when two of the given (flag, path) pairs name the same file; empty paths
// are skipped. Keeps an output from overwriting an input or another output.
void check_distinct_paths(const std::vector<std::pair<std::string, std::filesystem::path>>& paths);
// Whether the path's extension is `extension` (".exr"), ignoring case.
bool has_extension(const std::filesystem::path& path, std::string_view extension);

}  // namespace tilesplat::cli
