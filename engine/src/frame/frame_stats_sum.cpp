#include "frame/frame_stats_sum.h"

#include <algorithm>

namespace tilesplat {

void add_frame_stats(FrameStats& total, const FrameStats& frame, FrameCounts counts) {
  add_pass_times(total.passes, frame.passes);
  total.gpu_ms += frame.gpu_ms;
  total.depth_order_ms += frame.depth_order_ms;
  if (counts == FrameCounts::kDisjoint) {
    total.visible += frame.visible;
    total.intersections += frame.intersections;
  } else {
    total.visible = std::max(total.visible, frame.visible);
    total.intersections = std::max(total.intersections, frame.intersections);
  }
  total.sort_bits = std::max(total.sort_bits, frame.sort_bits);
  total.retries += frame.retries;
  total.submissions += frame.submissions;
  total.sort_fallbacks += frame.sort_fallbacks;
  total.uploaded_bytes += frame.uploaded_bytes;
  total.device_bytes = frame.device_bytes;
  total.peak_device_bytes = std::max(total.peak_device_bytes, frame.peak_device_bytes);
  total.scene_parts = std::max(total.scene_parts, frame.scene_parts);
  total.reused_sorted_lists = total.reused_sorted_lists && frame.reused_sorted_lists;
  total.complete = total.complete && frame.complete;
}

void add_pass_times(std::vector<PassTiming>& into, const std::vector<PassTiming>& from) {
  for (const PassTiming& pass : from) {
    auto it =
        std::find_if(into.begin(), into.end(), [&](const PassTiming& p) { return p.name == pass.name; });
    if (it == into.end())
      into.push_back(pass);
    else
      it->gpu_ms += pass.gpu_ms;
  }
}

}  // namespace tilesplat
