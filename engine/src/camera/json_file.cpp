#include "camera/json_file.h"

#include <fstream>
#include <string>

#include "tilesplat/scene_error.h"

namespace tilesplat {

nlohmann::json parse_json_file(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw SceneError(path.string() + ": cannot open file");
  try {
    return nlohmann::json::parse(stream);
  } catch (const nlohmann::json::exception& error) {
    throw SceneError(path.string() + ": invalid JSON: " + error.what());
  }
}

}  // namespace tilesplat
