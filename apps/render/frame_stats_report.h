// What tilesplat-render --stats prints: the frame's statistics and a LOD set's selection or a LOD tree's cut, one row each.
#pragma once

#include <string>

#include <cstdint>
#include <vector>

#include "tilesplat/lod_set.h"
#include "tilesplat/lod_tree.h"
#include "tilesplat/renderer.h"

namespace tilesplat::render_app {

// "name   value unit", the name and value in aligned columns.
void print_row(const std::string& name, const std::string& value, const std::string& unit);
// The device, each pass's GPU time, the frame's times, counts and memory, and the process's peak resident
// set.
void print_frame_stats(const FrameStats& stats, const DeviceInfo& device);
// How many chunks the frame drew at each level, and the Gaussians it drew against its budget.
void print_lod_selection(const LodSelection& selection);
// How many splats of a .rad LOD tree the frame drew, and how many of them are merged inner nodes.
void print_lod_tree_cut(const SplatLodTree& tree, const std::vector<uint32_t>& cut);

}  // namespace tilesplat::render_app
