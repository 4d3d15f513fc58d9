// tilesplat-render's frame: one camera rendered with the GPU renderer (whole, in parts under a memory
// budget, or a LOD set's levels under a splat budget) or the float64 reference, with the flags' lens.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "cli.h"
#include "render_options.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat::render_app {

// Renders one camera at a time; gpu_ms() and cpu_ms() give the last frame's time.
class FrameRenderer {
 public:
  FrameRenderer(const RenderOptions& options, const cli::LoadedScene& loaded);

  // `next_camera`, where given, is the next frame's: under --splat-budget its levels are read on the
  // streamer's thread while this frame renders.
  RenderImage render(const Camera& camera, const RenderSettings& base_settings,
                     const Camera* next_camera = nullptr);

  // The strategy the frames sort with ("auto" resolved on the device), for the EXR's provenance.
  std::string sort_strategy(const RenderSettings& settings) const;

  double gpu_ms() const { return gpu_ms_; }
  double cpu_ms() const { return cpu_ms_; }
  Renderer* gpu() const { return renderer_.get(); }
  // The levels the last frame drew, under --splat-budget (else empty).
  const LodSelection& lod_selection() const { return lod_selection_; }
  // The nodes of a .rad LOD tree the last frame drew, under --splat-budget (else empty).
  const std::vector<uint32_t>& lod_tree_cut() const { return lod_tree_cut_; }

 private:
  const GaussianScene* scene_;
  // A scene file's placed copies: under --memory-budget, when some move, or when their frame does not fit
  // the device (decide_holding merges them into merged_ otherwise).
  const SceneInstances* instances_;
  // A binary PLY, an SPZ or a SOG read part by part (--read-in-parts, or a large one): taken by every frame
  // in parts, or loaded into merged_ when its frame fits the device.
  const SceneInParts* file_in_parts_;
  GaussianScene merged_;
  const cli::LoadedLodSet* lod_;     // a LOD set drawn under --splat-budget
  LodSelection lod_selection_;
  std::unique_ptr<LodStreamer> lod_streamer_;  // reads each frame's levels, the next frame's ahead
  GaussianScene lod_scene_;                    // the levels (or the tree's cut) the last frame drew
  const cli::LoadedLodTree* lod_tree_;         // a .rad LOD tree drawn under --splat-budget
  std::vector<uint32_t> lod_tree_cut_;         // its nodes in lod_scene_
  bool warned_over_budget_ = false;
  LensFlags lens_;
  // The first frame's choice: the scene set once, or taken by each frame (in parts where it does not fit).
  void decide_holding(const Camera& camera, const RenderSettings& settings);
  // The PLY read part by part, loaded into merged_ and drawn from there.
  void load_file_whole();

  bool in_parts_ = false;  // --memory-budget, or a frame that does not fit the device
  bool decided_ = false;
  std::array<double, 3> scene_centre_ = {0, 0, 0};  // where the lens focuses unless --focus-distance says
  std::unique_ptr<Renderer> renderer_;
  double gpu_ms_ = 0, cpu_ms_ = 0;
};

}  // namespace tilesplat::render_app
