// libFuzzer harness for LOD set indexes (splat-transform's lod-meta.json, tilesplat/lod_set.h): the input is
// the JSON of an index in a folder that holds one chunk file, c.ply (8 Gaussians), for "filenames" to name.
// Every input must parse into a set whose levels add up and whose chunks have a slice per level, or throw a
// SceneError that names the file; a parsed set's levels load (the slices within c.ply) or throw one, and
// the choice of levels under a budget stays within it (or draws the coarsest levels, flagged over budget).
// See tests/fuzz/README.md.
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fuzz_checks.h"
#include "tilesplat/camera.h"
#include "tilesplat/lod_set.h"

namespace {

namespace fs = std::filesystem;

constexpr uint64_t kChunkGaussians = 8;

// A folder of this process's own (libFuzzer may run several processes side by side), with c.ply in it.
const fs::path& work_folder() {
  static const fs::path folder = [] {
    const fs::path path =
        fs::temp_directory_path() / ("tilesplat_fuzz_lod_set_" + std::to_string(::getpid()));
    fs::create_directories(path);
    std::ofstream ply(path / "c.ply");
    ply << "ply\nformat ascii 1.0\nelement vertex " << kChunkGaussians
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty float f_dc_0\nproperty float "
           "f_dc_1\n"
           "property float f_dc_2\nproperty float opacity\nproperty float scale_0\nproperty float scale_1\n"
           "property float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\n"
           "property float rot_3\nend_header\n";
    for (uint64_t i = 0; i < kChunkGaussians; ++i) ply << i << " 0 2 0.5 0.5 0.5 1 -3 -3 -3 1 0 0 0\n";
    return path;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path file = work_folder() / "lod-meta.json";
  const std::string prefix = file.string() + ": ";
  try {
    const tilesplat::LodSet set =
        tilesplat::LodSet::parse(std::string_view(reinterpret_cast<const char*>(data), size), file);
    FUZZ_CHECK(set.levels() >= 1);
    uint64_t total = 0;
    for (const tilesplat::LodChunk& chunk : set.chunks()) {
      FUZZ_CHECK(chunk.levels.size() == size_t(set.levels()));
      for (const tilesplat::LodSlice& slice : chunk.levels) {
        FUZZ_CHECK(slice.count == 0 || slice.file < set.files().size());
        total += slice.count;
      }
      for (size_t a = 0; a < 3; ++a) FUZZ_CHECK(chunk.min[a] <= chunk.max[a]);
    }
    uint64_t levels_total = 0;
    for (int level = 0; level < set.levels(); ++level) levels_total += set.level_size(level);
    FUZZ_CHECK(levels_total == total);

    const tilesplat::Camera camera = tilesplat::fuzz::camera_looking_at_origin(4);
    try {
      for (int level = 0; level < set.levels(); ++level) {
        const tilesplat::GaussianScene scene = set.load_level(level);
        FUZZ_CHECK(scene.size() == set.level_size(level) + set.environment_size());
      }
      for (const uint64_t budget : {uint64_t(1), uint64_t(10), uint64_t(1000)}) {
        const tilesplat::LodSelection selection = tilesplat::select_lod_levels(set, camera, budget);
        FUZZ_CHECK(selection.chunk_levels.size() == set.chunks().size());
        FUZZ_CHECK(selection.over_budget == (selection.splats > budget));
        FUZZ_CHECK(selection.splats <= std::max(budget, selection.coarsest_splats));
        FUZZ_CHECK(set.load_selection(selection).size() == selection.splats);
      }
    } catch (const tilesplat::SceneError& error) {
      FUZZ_CHECK(std::string(error.what()).starts_with(prefix));
    }
  } catch (const tilesplat::SceneError& error) {
    FUZZ_CHECK(std::string(error.what()).starts_with(prefix));
  }
  return 0;
}
