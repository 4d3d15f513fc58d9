// Reader for Spark 2's .rad files (scene/rad_file.h decodes them). A file with a LOD tree is read as its
// finest level, the tree's leaves (the source's Gaussians); tilesplat/lod_tree.h draws its other levels.
#include <string>

#include "scene/rad_file.h"
#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

namespace tilesplat::detail {

GaussianScene read_rad(std::span<const std::byte> data, std::string_view name, const FileLoader& load_chunk,
                       const LoadOptions& options, LoadReport* report) {
  if (data.empty()) fail(name, "empty file, not a .rad file");
  const RadFile file(data, name, load_chunk);
  const std::vector<uint32_t> leaves = file.leaves();
  GaussianScene scene = file.decode(leaves);
  finish_scene(scene, name, options, file.description().format(leaves.size()), "1", report);
  return scene;
}

}  // namespace tilesplat::detail
