// Opening and parsing the JSON files of the camera readers, with errors that name the file.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

namespace tilesplat {

// Throws SceneError "FILE: cannot open file" or "FILE: invalid JSON: ..." (the parser's message
// carries the line and column, or the overflowing number literal).
nlohmann::json parse_json_file(const std::filesystem::path& path);

}  // namespace tilesplat
