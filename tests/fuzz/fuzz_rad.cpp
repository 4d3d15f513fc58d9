// libFuzzer harness for Spark's .rad reader (scene/rad_file.h) and its LOD tree (tilesplat/lod_tree.h). The
// checks are fuzz_checks.h's check_reader, and for a file with a LOD tree: SplatLodTree::parse accepts exactly
// what read_rad accepts, every level and every budgeted cut is a cut of the tree (each leaf under exactly
// one of its nodes) within its budget, and loads finite Gaussians. See tests/fuzz/README.md.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_checks.h"
#include "scene/scene_readers.h"
#include "tilesplat/lod_tree.h"

namespace {

// Every leaf has exactly one node of `cut` (sorted) on its way from the root.
bool is_cut(const tilesplat::SplatLodTree& tree, const std::vector<uint32_t>& cut) {
  if (!std::is_sorted(cut.begin(), cut.end())) return false;
  std::vector<std::pair<uint32_t, int>> stack = {{0, 0}};
  while (!stack.empty()) {
    const auto [node, above] = stack.back();
    stack.pop_back();
    const int here = above + (std::binary_search(cut.begin(), cut.end(), node) ? 1 : 0);
    if (tree.child_count(node) == 0 && here != 1) return false;
    for (uint32_t k = 0; k < tree.child_count(node); ++k) stack.push_back({tree.child_start(node) + k, here});
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  bool read = false, tree_read = false;
  try {
    tilesplat::detail::read_rad(bytes, "fuzz-input.rad", nullptr, {}, nullptr);
    read = true;
  } catch (const tilesplat::SceneError&) {
  }
  try {
    const tilesplat::SplatLodTree tree = tilesplat::SplatLodTree::parse(bytes, "fuzz-input.rad");
    tree_read = true;
    FUZZ_CHECK(tree.levels() >= 1 && tree.levels() <= 256);
    for (int level = 0; level < tree.levels(); level += std::max(1, tree.levels() / 8)) {
      const std::vector<uint32_t> nodes = tree.level_nodes(level);
      FUZZ_CHECK(is_cut(tree, nodes));
    }
    const tilesplat::Camera camera = tilesplat::fuzz::camera_looking_at_origin(3);
    for (uint64_t budget : {uint64_t(0), uint64_t(1), uint64_t(7), uint64_t(100)}) {
      const tilesplat::LodTreeCut cut = tree.select(camera, budget);
      FUZZ_CHECK(is_cut(tree, cut.nodes));
      FUZZ_CHECK(cut.nodes.size() <= std::max<uint64_t>(budget, 1));
      const tilesplat::GaussianScene scene = tree.load(cut.nodes);
      FUZZ_CHECK(tilesplat::fuzz::all_finite(scene.positions) && tilesplat::fuzz::all_finite(scene.log_scales));
    }
  } catch (const tilesplat::SceneError&) {
  }
  // A tree parses exactly where the file reads (and has a tree).
  FUZZ_CHECK(!tree_read || read);
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input",
                                       [](auto input, auto name, const auto& options, auto* report) {
                                         return tilesplat::detail::read_rad(input, name, nullptr, options, report);
                                       });
}
