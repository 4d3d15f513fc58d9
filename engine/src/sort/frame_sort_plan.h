// FrameSortPlan: how a frame uses a sort strategy (SortStrategy::frame_plan), a value of the frame's
// plan (frame/frame_plan.h) without the strategy or any Vulkan type.
#pragma once

namespace tilesplat {

// How a frame uses a strategy. A global sort runs twice: the Gaussians by depth, then the (tile,
// Gaussian) pairs by tile id. A strategy that bins by tile itself sorts each pair's
// (tile << 32 | depth bits) key once instead.
enum class FrameSortPlan { kDepthThenTile, kTileDepthPairs };

}  // namespace tilesplat
