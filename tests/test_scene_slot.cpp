// SceneSlot (engine/src/frame/scene_slot.h), tested without a device: the generation that makes tile
// lists stale, the identity that accumulated samples are of, moving copies placed only when their time
// changes, and the refusal of a frame of "the scene set" while the buffers hold a part.
#include <gtest/gtest.h>

#include <stdexcept>

#include "frame/scene_slot.h"

namespace tilesplat {
namespace {

GaussianScene one_gaussian() {
  GaussianScene scene;
  scene.positions = {0, 0, 0};
  scene.log_scales = {-2, -2, -2};
  scene.rotations = {1, 0, 0, 0};
  scene.opacity_logits = {1};
  scene.sh = {0.5f, 0.5f, 0.5f};
  return scene;
}

// A scene file's one model, moving 1 unit along x over the shutter.
SceneInstances moving_copy() {
  SceneInstances instances;
  instances.files.push_back(one_gaussian());
  SceneInstances::Instance copy;
  copy.file = 0;
  copy.end_transform = ModelTransform{};
  copy.end_transform->translation = {1, 0, 0};
  instances.instances.push_back(copy);
  return instances;
}

TEST(SceneSlot, UploadsMakeListsStaleAndScenesChangeTheIdentity) {
  SceneSlot slot;
  slot.uploaded();
  slot.set_whole();
  const uint64_t generation = slot.generation(), identity = slot.identity();
  slot.uploaded();  // the same scene's copies placed anew: new contents, the same scene
  EXPECT_EQ(slot.generation(), generation + 1);
  EXPECT_EQ(slot.identity(), identity);
  slot.uploaded();
  slot.set_whole();
  EXPECT_EQ(slot.identity(), identity + 1);
}

TEST(SceneSlot, MovingCopiesArePlacedOnlyWhenTheirTimeChanges) {
  SceneSlot slot;
  EXPECT_FALSE(slot.moving_copies_at(0.5)) << "nothing moves";
  slot.set_whole();
  slot.keep_moving_copies(moving_copy());
  ASSERT_TRUE(slot.has_moving_copies());
  EXPECT_FALSE(slot.moving_copies_at(0.0)) << "uploaded at time 0 already";
  const std::optional<GaussianScene> half = slot.moving_copies_at(0.5);
  ASSERT_TRUE(half);
  EXPECT_FLOAT_EQ(half->positions[0], 0.5f);
  slot.placed(0.5);
  EXPECT_FALSE(slot.moving_copies_at(0.5));
  ASSERT_TRUE(slot.moving_copies_at(1.0));
  EXPECT_FLOAT_EQ(slot.moving_copies_at(1.0)->positions[0], 1.0f);
  slot.set_whole();  // another scene set: nothing moves any more
  EXPECT_FALSE(slot.has_moving_copies());
}

TEST(SceneSlot, PartsRefuseOtherFramesUntilAWholeSceneIsSet) {
  SceneSlot slot;
  slot.set_whole();
  slot.keep_moving_copies(moving_copy());
  const uint64_t identity = slot.identity();
  EXPECT_TRUE(slot.start_parts(1 << 20)) << "a whole scene's buffers go";
  EXPECT_TRUE(slot.holds_part());
  EXPECT_FALSE(slot.has_moving_copies());
  EXPECT_EQ(slot.identity(), identity + 1);
  {
    const SceneSlot::DrawingParts drawing(slot);
    EXPECT_NO_THROW(slot.check_whole_scene());
  }
  EXPECT_THROW(slot.check_whole_scene(), std::logic_error);
  EXPECT_FALSE(slot.start_parts(1 << 20)) << "parts of the same budget reuse the buffers";
  EXPECT_TRUE(slot.start_parts(2 << 20)) << "another budget sizes them anew";
  slot.set_whole();
  EXPECT_FALSE(slot.holds_part());
  EXPECT_NO_THROW(slot.check_whole_scene());
}

}  // namespace
}  // namespace tilesplat
