// A LOD set drawn under --splat-budget in the viewer: each frame asks for the levels its camera calls for,
// which a LodStreamer reads on a thread of its own while the window goes on drawing the levels it has. A .rad
// LOD tree is held whole: each frame's cut is chosen and decoded before it (a few ms; no thread).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/lod_tree.h"
#include "tilesplat/renderer.h"
#include "tilesplat/vulkan_interop.h"

namespace tilesplat::viewer {

class LodView {
 public:
  // `wake` runs on the streamer's thread when a read is done (glfwPostEmptyEvent: the event loop then
  // sees arrived() and renders).
  LodView(const LodSet& set, uint64_t splat_budget, std::function<void()> wake);
  LodView(const SplatLodTree& tree, uint64_t splat_budget);

  // Before a frame seen from `camera`: asks for its levels, and sets on `renderer` the newest levels read
  // (the first frame waits for its own: there is nothing else to draw).
  void prepare_frame(Renderer& renderer, const Camera& camera);
  // The last camera's levels on `renderer`, read to the end (an EXR screenshot draws those).
  void finish(Renderer& renderer);
  // Whether levels were read since the last call: the window should render them.
  bool arrived() { return arrived_.exchange(false); }

  // " | N splats (LOD)", with "; loading M" while the camera's levels are read.
  std::string title() const;
  // ", levels read N times on the streamer's thread (median, longest), K frames drew the levels before".
  std::string summary() const;

 private:
  void set_levels(Renderer& renderer, const std::optional<LodLoad>& loaded);

  // Set on the streamer's thread; declared before the streamer, which may set it until it is destroyed.
  std::atomic<bool> arrived_ = false;
  std::unique_ptr<LodStreamer> streamer_;  // a LOD set's
  const SplatLodTree* tree_ = nullptr;     // or a LOD tree's, with its budget and last cut
  uint64_t tree_budget_ = 0;
  std::vector<uint32_t> tree_cut_;
  bool drawn_ = false;           // the renderer has levels of the set
  uint64_t drawn_splats_ = 0;    // their Gaussians
  uint64_t wanted_splats_ = 0;   // those of the levels the last camera calls for
  std::vector<double> load_ms_;  // each read's time on the streamer's thread
  int frames_behind_ = 0;        // frames drawn while the camera's levels were read
};

}  // namespace tilesplat::viewer
