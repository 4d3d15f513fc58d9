// The statistics of frames rendered one after another into one image (FrameStats): the samples an averaged
// frame takes (a lens, a shutter), the depth-ordered parts of a scene past the device, the bands of an image
// past it. Each adds its frame to the total the same way, but for what it counts.
#pragma once

#include <vector>

#include "tilesplat/renderer.h"

namespace tilesplat {

// Whether the frames count different Gaussians and pairs (the parts of a scene, the bands of an image: each
// counts its own, and the total is their sum) or the same ones again (averaged samples, each the whole
// frame: the total is the largest).
enum class FrameCounts { kDisjoint, kRepeated };

// Adds `frame` to `total`: the GPU time and each pass's summed, and the retries, submissions, sort
// fallbacks and uploads; visible Gaussians and intersections by `counts`; the sort bits and scene parts the
// largest; device memory the last frame's and its peak the largest; lists reused and the image complete only
// where every frame's were. The callers count their frames (samples, scene_parts, image_bands) themselves.
void add_frame_stats(FrameStats& total, const FrameStats& frame, FrameCounts counts);

// Adds each pass's GPU time of `from` to the pass of that name in `into` (appended where it has none).
void add_pass_times(std::vector<PassTiming>& into, const std::vector<PassTiming>& from);

}  // namespace tilesplat
