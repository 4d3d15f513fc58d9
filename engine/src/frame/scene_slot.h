// SceneSlot: what the renderer's scene buffers hold, as the frames must know it.
//   - generation: counts the uploads of new contents (a scene set, each part of a scene in parts, moving
//     copies placed anew): tile lists built on an earlier generation are stale (SceneShape::generation);
//   - identity: counts the scenes (set_scene, and each render in parts), not the placings of moving copies:
//     what lens and shutter samples summed across calls are of (FrameAccumulator::Samples);
//   - the placed copies that move (set_scene of SceneInstances) and the time the buffers show them at;
//   - a part of a scene rendered in parts (renderer_parts.cpp) rather than a whole scene, and the memory
//     budget the parts' buffers were sized for: a frame of "the scene set" is refused then.
// The uploads themselves are the renderer's (FrameResources); this is their record. No Vulkan: tested
// without a device (tests/test_scene_slot.cpp).
#pragma once
#include <cstdint>
#include <optional>

#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {

class SceneSlot {
 public:
  // New contents were uploaded (any: a scene, a part, copies placed anew).
  void uploaded() { ++generation_; }
  // A whole scene was set (after its upload): a new scene, no moving copies, no parts.
  void set_whole();
  // The scene set was SceneInstances whose copies move, uploaded where they are at time 0 (set_whole first).
  void keep_moving_copies(SceneInstances copies);
  bool has_moving_copies() const { return moving_copies_.has_value(); }
  // The merged scene to upload for the moving copies at `time`, or nothing when the buffers show them
  // there already (or none move); once it is uploaded, placed(time).
  std::optional<GaussianScene> moving_copies_at(double time) const;
  void placed(double time) { moving_copies_time_ = time; }

  // A render in parts under `budget` starts: a new scene, whose parts follow; no moving copies. Returns
  // whether the buffers must let go of what they hold first (a whole scene, or parts sized for another
  // budget, which the parts would not reuse).
  bool start_parts(uint64_t budget);
  bool holds_part() const { return in_parts_; }
  // While a render in parts draws its parts (a scope), its frames may run on a part; any other frame
  // of "the scene set" throws std::logic_error (check_whole_scene).
  class DrawingParts {
   public:
    explicit DrawingParts(SceneSlot& slot) : slot_(slot) { slot_.drawing_parts_ = true; }
    ~DrawingParts() { slot_.drawing_parts_ = false; }
    DrawingParts(const DrawingParts&) = delete;
    DrawingParts& operator=(const DrawingParts&) = delete;

   private:
    SceneSlot& slot_;
  };
  void check_whole_scene() const;

  uint64_t generation() const { return generation_; }
  uint64_t identity() const { return identity_; }

 private:
  uint64_t generation_ = 0;
  uint64_t identity_ = 0;
  std::optional<SceneInstances> moving_copies_;
  double moving_copies_time_ = 0;
  bool in_parts_ = false;      // the buffers hold a part of a scene, not a whole one
  uint64_t parts_budget_ = 0;  // the memory budget those parts were sized for
  bool drawing_parts_ = false;
};

}  // namespace tilesplat
