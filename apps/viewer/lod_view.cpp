#include "lod_view.h"

#include <algorithm>
#include <chrono>

#include "cli.h"

namespace tilesplat::viewer {

namespace cli = tilesplat::cli;

LodView::LodView(const LodSet& set, uint64_t splat_budget, std::function<void()> wake)
    : streamer_(
          std::make_unique<LodStreamer>(set, splat_budget, LoadOptions{}, [this, wake = std::move(wake)] {
            arrived_ = true;
            if (wake) wake();
          })) {}

LodView::LodView(const SplatLodTree& tree, uint64_t splat_budget) : tree_(&tree), tree_budget_(splat_budget) {}

void LodView::prepare_frame(Renderer& renderer, const Camera& camera) {
  if (tree_) {
    const auto start = std::chrono::steady_clock::now();
    LodTreeCut cut = tree_->select(camera, tree_budget_);
    wanted_splats_ = cut.nodes.size();
    if (drawn_ && cut.nodes == tree_cut_) return;
    wait_for_frame(renderer);  // the frame before may still read the scene it replaces
    renderer.set_scene(tree_->load(cut.nodes));
    tree_cut_ = std::move(cut.nodes);
    drawn_ = true;
    drawn_splats_ = wanted_splats_;
    load_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    return;
  }
  wanted_splats_ = streamer_->request(camera).splats;
  set_levels(renderer, drawn_ ? streamer_->take() : streamer_->wait_and_take());
  if (streamer_->busy()) ++frames_behind_;
}

void LodView::finish(Renderer& renderer) {
  if (tree_) return;  // the last camera's cut is already drawn
  wait_for_frame(renderer);  // the last frame may still read the scene
  set_levels(renderer, streamer_->wait_and_take());
}

void LodView::set_levels(Renderer& renderer, const std::optional<LodLoad>& loaded) {
  if (!loaded) return;
  renderer.set_scene(loaded->scene);
  drawn_ = true;
  drawn_splats_ = loaded->selection.splats;
  load_ms_.push_back(loaded->load_ms);
}

std::string LodView::title() const {
  const bool loading = !tree_ && (wanted_splats_ != drawn_splats_ || streamer_->busy());
  return " | " + cli::group_thousands(drawn_splats_) + " splats (LOD" +
         (loading ? "; loading " + cli::group_thousands(wanted_splats_) : "") + ")";
}

std::string LodView::summary() const {
  std::vector<double> sorted = load_ms_;
  std::sort(sorted.begin(), sorted.end());
  std::string text = tree_ ? ", tree cuts decoded " + std::to_string(sorted.size()) +
                                 (sorted.size() == 1 ? " time" : " times") + " before their frames"
                           : ", levels read " + std::to_string(sorted.size()) +
                                 (sorted.size() == 1 ? " time" : " times") + " on the streamer's thread";
  if (!sorted.empty())
    text += " (median " + cli::format_fixed(sorted[sorted.size() / 2], 1) + " ms, longest " +
            cli::format_fixed(sorted.back(), 1) + " ms)";
  if (tree_) return text;
  return text + ", " + std::to_string(frames_behind_) + (frames_behind_ == 1 ? " frame" : " frames") +
         " drew the levels before while they were read";
}

}  // namespace tilesplat::viewer
