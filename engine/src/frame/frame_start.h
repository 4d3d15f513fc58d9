// FrameStart: what a frame was planned as and started from, kept until it completes for its statistics
// and for what it leaves to the next frames (Renderer::Impl::begin_frame makes it, end_frame reads it).
#pragma once
#include <chrono>
#include <cstdint>

#include "frame/frame_accumulator.h"
#include "frame/frame_plan.h"

namespace tilesplat {

class SortStrategy;

struct FrameStart {
  FramePlan plan;
  SortStrategy* sorter = nullptr;  // the strategy the plan sorts with (the renderer owns it)
  uint64_t fallbacks_before = 0;   // SortStrategy::stall_fallbacks when the frame started
  std::chrono::steady_clock::time_point time;
  FrameAccumulator::FrameSums sums;  // what it leaves in the accumulated sums
};

}  // namespace tilesplat
