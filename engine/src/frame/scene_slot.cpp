#include "frame/scene_slot.h"

#include <stdexcept>
#include <utility>

namespace tilesplat {

void SceneSlot::set_whole() {
  ++identity_;
  moving_copies_.reset();
  in_parts_ = false;
}

void SceneSlot::keep_moving_copies(SceneInstances copies) {
  moving_copies_ = std::move(copies);
  moving_copies_time_ = 0.0;
}

std::optional<GaussianScene> SceneSlot::moving_copies_at(double time) const {
  if (!moving_copies_ || time == moving_copies_time_) return std::nullopt;
  return merge_instances(*moving_copies_, time);
}

bool SceneSlot::start_parts(uint64_t budget) {
  const bool release = !in_parts_ || parts_budget_ != budget;
  in_parts_ = true;  // from the first upload on, even if a part fails
  parts_budget_ = budget;
  ++generation_;
  ++identity_;
  moving_copies_.reset();  // the buffers hold parts from now on
  return release;
}

void SceneSlot::check_whole_scene() const {
  if (in_parts_ && !drawing_parts_)
    throw std::logic_error(
        "the renderer holds the last part of a scene rendered in parts (render(scene, camera, settings) "
        "under a memory budget), not a whole scene: call set_scene before render(camera, settings)");
}

}  // namespace tilesplat
