// The float64 reference's per-pixel order machinery (reference/pixel_order.h): the window the GPU's
// re-sorting composite keeps, item by item.
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "reference/pixel_order.h"

namespace tilesplat::reference {
namespace {

std::vector<int> released_order(size_t capacity, const std::vector<std::pair<double, int>>& items) {
  std::vector<int> released;
  DepthQueue<int> queue(capacity);
  auto release = [&](int item) { released.push_back(item); };
  for (const auto& [t, item] : items) queue.offer(t, item, release);
  queue.flush(release);
  return released;
}

TEST(PixelOrder, QueueReleasesTheNearerOfItsFrontAndTheNewItem) {
  // Depths 5 3 4 1 2 through a queue of 2: 5 3 wait; 4 releases 3 (nearer than 4), keeps 4 5; 1 is
  // nearer than the front 4 and leaves at once; 2 likewise; the end releases 4 5.
  EXPECT_EQ(released_order(2, {{5, 0}, {3, 1}, {4, 2}, {1, 3}, {2, 4}}), (std::vector<int>{1, 3, 4, 2, 0}));
  // Capacity 1 swaps neighbours at most: 3 is held, 1 passes it, 2 passes it, 3 leaves last.
  EXPECT_EQ(released_order(1, {{3, 0}, {1, 1}, {2, 2}}), (std::vector<int>{1, 2, 0}));
  // A tie with the front: the new item leaves first; ties inside keep their arrival order.
  EXPECT_EQ(released_order(1, {{1, 0}, {1, 1}}), (std::vector<int>{1, 0}));
  EXPECT_EQ(released_order(3, {{2, 0}, {2, 1}, {1, 2}}), (std::vector<int>{2, 0, 1}));
  // Capacity 0: a stable sort of everything.
  EXPECT_EQ(released_order(0, {{3, 0}, {1, 1}, {3, 2}, {0, 3}}), (std::vector<int>{3, 1, 0, 2}));
}

}  // namespace
}  // namespace tilesplat::reference
