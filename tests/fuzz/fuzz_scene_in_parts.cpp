// libFuzzer harness for what reads a scene file by its path before any reader runs: the file dispatch of
// SceneInParts::open (a binary PLY, an SPZ, a SOG zip or meta.json, told by content) and the header count
// readers of SceneInParts::whole_scene_bytes (tilesplat-render's choice between reading whole and in parts,
// made from the header alone). The input is written to a file of this process's own, as a user's file would
// be. The checks: whole_scene_bytes never throws; open loads a scene or throws a SceneError naming the file;
// a scene it opens is load_scene's of the same file, bit for bit; and a count reader that sized the file
// sized it at least as large as the arrays it holds. See tests/fuzz/README.md.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

#include "fuzz_checks.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_in_parts.h"

namespace {

// This process's input file, written anew for each input and removed when the process exits.
struct InputFile {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("fuzz_scene_in_parts_" + std::to_string(getpid()) + ".bin");
  ~InputFile() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};
const std::filesystem::path& input_path() {
  static const InputFile file;
  return file.path;
}

// The bytes of the arrays a scene holds.
uint64_t array_bytes(const tilesplat::GaussianScene& scene) {
  return 4 * (scene.positions.size() + scene.log_scales.size() + scene.rotations.size() +
              scene.opacity_logits.size() + scene.sh.size() + scene.normals.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path& path = input_path();
  {
    std::FILE* file = std::fopen(path.c_str(), "wb");
    FUZZ_CHECK(file != nullptr);
    FUZZ_CHECK(size == 0 || std::fwrite(data, 1, size, file) == size);
    FUZZ_CHECK(std::fclose(file) == 0);
  }
  const uint64_t declared = tilesplat::SceneInParts::whole_scene_bytes(path);  // never throws
  std::optional<tilesplat::SceneInParts> parts;
  try {
    tilesplat::LoadReport report;
    parts = tilesplat::SceneInParts::open(path, {}, &report);
  } catch (const tilesplat::SceneError& error) {
    FUZZ_CHECK(std::string(error.what()).find(path.string()) != std::string::npos);
    return 0;
  }
  const tilesplat::GaussianScene from_parts = parts->load();
  const tilesplat::GaussianScene whole = tilesplat::load_scene(path);  // must read what open read
  tilesplat::fuzz::check_same_gaussians(from_parts, whole);
  FUZZ_CHECK(parts->size() == whole.size());
  FUZZ_CHECK(parts->sh_degree() == whole.sh_degree);
  // An SPZ's or a SOG's count readers size the arrays from the header: 0 means "not told from it" (a version
  // 1 SOG), any other count covers the arrays loaded. (A PLY's is its file size, which is not a bound on
  // arrays of another width than its properties'.)
  const bool ply = size >= 3 && data[0] == 'p' && data[1] == 'l' && data[2] == 'y';
  FUZZ_CHECK(ply || declared == 0 || declared >= array_bytes(whole));
  return 0;
}
