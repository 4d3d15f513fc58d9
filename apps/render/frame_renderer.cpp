#include "frame_renderer.h"

#include <chrono>
#include <optional>
#include <stdexcept>

#include "tilesplat/reference.h"
#include "tilesplat/scene_description.h"

namespace tilesplat::render_app {

FrameRenderer::FrameRenderer(const RenderOptions& options, const cli::LoadedScene& loaded)
    : scene_(&loaded.scene),
      instances_(loaded.instances ? &*loaded.instances : nullptr),
      file_in_parts_(loaded.in_parts ? &*loaded.in_parts : nullptr),
      lod_(loaded.lod && loaded.lod->splat_budget > 0 ? &*loaded.lod : nullptr),
      lod_tree_(loaded.lod_tree && loaded.lod_tree->splat_budget > 0 ? &*loaded.lod_tree : nullptr),
      lens_(options.lens),
      in_parts_(options.memory_budget > 0) {
  if (lens_.enabled()) {
    const Bounds bounds = loaded.bounds();
    scene_centre_ = {bounds.center[0], bounds.center[1], bounds.center[2]};
  }
  if (lod_) lod_streamer_ = std::make_unique<LodStreamer>(*lod_->set, lod_->splat_budget);
  if (options.reference) {
    if (file_in_parts_) load_file_whole();  // the float64 reference takes a whole scene
    return;
  }
  renderer_ = Renderer::create(cli::renderer_options(options.common));
  // Under a memory budget each frame takes the scene (in parts where it does not fit); under a splat
  // budget each frame draws the levels its camera calls for. Otherwise the first frame decides: a scene
  // whose frame fits the device is set once, one that does not is rendered in parts every frame.
}

void FrameRenderer::decide_holding(const Camera& camera, const RenderSettings& settings) {
  if (decided_) return;
  decided_ = true;
  if (in_parts_ || lod_ || lod_tree_) return;
  if (instances_) {
    // A scene file's copies stay placed copies of their files, taken by every frame (in parts where they
    // do not fit), under --memory-budget, when some move (each time of a shutter places them anew), and
    // when their frame does not fit the device: the parts place them part by part, and the merged scene
    // (5.5 GB for 72 copies of the 500k playbot) is never held. Otherwise they are merged and set once.
    if (instances_->moves() || renderer_->renders_in_parts(*instances_, camera, settings)) return;
    merged_ = merge_instances(*instances_);
    scene_ = &merged_;
    instances_ = nullptr;
  }
  if (file_in_parts_) {
    // A PLY read part by part stays in its file while its frames are drawn in parts; one whose frame fits
    // the device is loaded and set once.
    if (renderer_->renders_in_parts(*file_in_parts_, camera, settings)) {
      in_parts_ = true;
      return;
    }
    load_file_whole();
  }
  in_parts_ = renderer_->renders_in_parts(*scene_, camera, settings);
  if (!in_parts_) renderer_->set_scene(*scene_);
}

void FrameRenderer::load_file_whole() {
  merged_ = file_in_parts_->load();
  scene_ = &merged_;
  file_in_parts_ = nullptr;
}

RenderImage FrameRenderer::render(const Camera& camera, const RenderSettings& base_settings,
                                  const Camera* next_camera) {
  RenderSettings settings = base_settings;
  // The flags' lens, its focus following the frame's camera, over the scene file's lens for the view.
  if (lens_.enabled()) settings.lens = lens_for_frame(lens_, camera, scene_centre_);
  if (lod_) {
    // The levels this camera calls for: read ahead during the frame before where they were its next
    // camera's (a request for the levels already asked for is none), or now; none comes where they are
    // the last frame's.
    lod_selection_ = lod_streamer_->request(camera);
    if (std::optional<LodLoad> loaded = lod_streamer_->wait_and_take()) lod_scene_ = std::move(loaded->scene);
    if (next_camera) lod_streamer_->request(*next_camera);
    if (lod_selection_.over_budget && !warned_over_budget_) {
      cli::print_warning(kProgram, "--splat-budget " + std::to_string(lod_->splat_budget) +
                                       " is below what the coarsest levels in view draw (" +
                                       std::to_string(lod_selection_.coarsest_splats) +
                                       " Gaussians): those frames draw the coarsest levels");
      warned_over_budget_ = true;
    }
  }
  if (lod_tree_) {
    // The tree's cut for this camera, decoded from the file held whole; a cut like the last frame's is kept.
    const LodTreeCut cut = lod_tree_->tree->select(camera, lod_tree_->splat_budget);
    if (cut.nodes != lod_tree_cut_) {  // a cut holds the root at least: the first frame's always differs
      lod_scene_ = lod_tree_->tree->load(cut.nodes);
      lod_tree_cut_ = cut.nodes;
    }
  }
  if (renderer_) decide_holding(camera, settings);  // may merge a scene file's copies into scene_
  const bool per_frame_scene = lod_ || lod_tree_;
  const GaussianScene& scene = per_frame_scene ? lod_scene_ : *scene_;
  RenderImage image;
  if (renderer_) {
    image = file_in_parts_        ? renderer_->render(*file_in_parts_, camera, settings)
            : instances_          ? renderer_->render(*instances_, camera, settings)
            : !in_parts_ && !per_frame_scene ? renderer_->render(camera, settings)
                                  : renderer_->render(scene, camera, settings);
    gpu_ms_ = renderer_->last_frame_stats().gpu_ms;
    cpu_ms_ = renderer_->last_frame_stats().cpu_ms;
  } else {
    const auto start = std::chrono::steady_clock::now();
    image = instances_ ? render_reference(*instances_, camera, settings)
                       : render_reference(scene, camera, settings);
    cpu_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    gpu_ms_ = 0;
  }
  // The camera's size, or the region's (--region).
  const int width = settings.region.whole() ? camera.width : settings.region.width;
  const int height = settings.region.whole() ? camera.height : settings.region.height;
  if (image.width != width || image.height != height || image.rgba.size() != image.pixels() * 4)
    throw std::runtime_error("the renderer returned a " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " image for a " + std::to_string(width) + "x" +
                             std::to_string(height) + " frame");
  if (!settings.depth) image.depth.clear();
  if (!settings.splat_count) image.splat_count.clear();
  return image;
}

std::string FrameRenderer::sort_strategy(const RenderSettings& settings) const {
  return renderer_ ? renderer_->sort_strategy_for(settings.sort) : "none (float64 CPU reference)";
}

}  // namespace tilesplat::render_app
