// Writing a file so that readers only ever see the old content or the complete new content, and a
// crash after the rename finds the new content on the storage (the file and its directory are
// synced). tilesplat::write_file_atomically (tilesplat/image.h) is the public form for contents in
// memory; EXR and PNG writers hand their library a temporary path through this one.
#pragma once

#include <filesystem>
#include <functional>

namespace tilesplat::detail {

// Calls `write` with a fresh temporary path in the same directory as `target` (same file system,
// so the final rename is atomic), syncs the file, renames it over `target` and syncs the directory.
//
// Throws std::runtime_error naming `target` when its directory does not exist, or when `write` or
// the rename fails; in that case the temporary file is removed and `target` is left untouched.
// The original exception is kept as the nested exception (std::throw_with_nested).
void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& temp)>& write);

}  // namespace tilesplat::detail
