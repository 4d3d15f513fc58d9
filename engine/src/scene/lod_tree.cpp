// SplatLodTree: the cuts of a .rad LOD tree (tilesplat/lod_tree.h), on the nodes scene/rad_file.h decodes.
#include "tilesplat/lod_tree.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <queue>
#include <stdexcept>
#include <string>

#include "scene/rad_file.h"
#include "scene/scene_reading.h"

namespace tilesplat {

namespace {
constexpr double kLevelRatio = 1.25;  // Spark's level view: each level's largest node 1/1.25 of the one above's
constexpr int kMaxLevels = 256;
}  // namespace

struct SplatLodTree::Impl {
  std::string name;
  detail::RadFile file;
  int spark_levels = 0;  // K: Spark's level K refines every inner node of positive size
  double root_size = 0;
};

SplatLodTree::SplatLodTree(std::string name, detail::RadFile&& file)
    : impl_(new Impl{std::move(name), std::move(file)}) {
  const detail::RadFile& rad = impl_->file;
  if (!rad.has_lod_tree()) detail::fail(impl_->name, "a .rad without a LOD tree: read it with load_scene");
  impl_->root_size = rad.node_size(0);
  double smallest_inner = INFINITY;
  for (size_t i = 0; i < rad.size(); ++i)
    if (rad.child_count(i) > 0 && rad.node_size(i) > 0) smallest_inner = std::min(smallest_inner, rad.node_size(i));
  if (std::isfinite(impl_->root_size) && impl_->root_size > 0 && std::isfinite(smallest_inner))
    impl_->spark_levels = std::min<int>(
        kMaxLevels - 1,
        static_cast<int>(std::floor(std::log(impl_->root_size / smallest_inner) / std::log(kLevelRatio))) + 1);
}
SplatLodTree::SplatLodTree(SplatLodTree&&) noexcept = default;
SplatLodTree& SplatLodTree::operator=(SplatLodTree&&) noexcept = default;
SplatLodTree::~SplatLodTree() = default;

SplatLodTree SplatLodTree::open(const std::filesystem::path& path) {
  detail::FileContents contents;
  detail::open_scene_file(path, contents);
  std::string name = path.string();
  if (!detail::is_rad(contents.bytes())) detail::fail(name, "not a .rad file (no RAD0 or RADC magic)");
  detail::RadFile file(contents.bytes(), name, detail::sibling_loader(path));
  return SplatLodTree(std::move(name), std::move(file));
}

SplatLodTree SplatLodTree::parse(std::span<const std::byte> data, std::string_view name) {
  if (!detail::is_rad(data)) detail::fail(name, "not a .rad file (no RAD0 or RADC magic)");
  detail::RadFile file(data, name, nullptr);
  return SplatLodTree(std::string(name), std::move(file));
}

size_t SplatLodTree::nodes() const { return impl_->file.size(); }
int SplatLodTree::sh_degree() const { return impl_->file.sh_degree(); }
int SplatLodTree::levels() const { return impl_->spark_levels + 1; }

namespace {
uint32_t checked(const detail::RadFile& file, const std::string& name, uint32_t node) {
  if (node >= file.size())
    throw std::out_of_range(name + ": no node " + std::to_string(node) + " (it has " + std::to_string(file.size()) +
                            ")");
  return node;
}
}  // namespace

uint32_t SplatLodTree::child_count(uint32_t node) const {
  return impl_->file.child_count(checked(impl_->file, impl_->name, node));
}
uint32_t SplatLodTree::child_start(uint32_t node) const {
  return impl_->file.child_start(checked(impl_->file, impl_->name, node));
}
double SplatLodTree::node_size(uint32_t node) const {
  return impl_->file.node_size(checked(impl_->file, impl_->name, node));
}

std::vector<uint32_t> SplatLodTree::level_nodes(int level) const {
  if (level < 0 || level >= levels())
    throw std::out_of_range(impl_->name + ": no level " + std::to_string(level) + " (it has " +
                            std::to_string(levels()) + ")");
  const detail::RadFile& file = impl_->file;
  if (level == 0) return file.leaves();
  const double threshold = impl_->root_size / std::pow(kLevelRatio, impl_->spark_levels - level);
  std::vector<uint32_t> cut, stack = {0};
  while (!stack.empty()) {
    const uint32_t node = stack.back();
    stack.pop_back();
    if (file.child_count(node) == 0 || file.node_size(node) <= threshold) {
      cut.push_back(node);
      continue;
    }
    for (uint32_t c = 0; c < file.child_count(node); ++c) stack.push_back(file.child_start(node) + c);
  }
  std::sort(cut.begin(), cut.end());
  return cut;
}

LodTreeCut SplatLodTree::select(const Camera& camera, uint64_t splat_budget) const {
  const detail::RadFile& file = impl_->file;
  const auto pixel_scale = [&](uint32_t node) {
    const float* c = file.center(node);
    const double dx = c[0] - camera.position[0], dy = c[1] - camera.position[1], dz = c[2] - camera.position[2];
    const double scale = file.node_size(node) / std::max(std::sqrt(dx * dx + dy * dy + dz * dz), 1e-6);
    return std::isnan(scale) ? 0.0 : scale;  // a NaN would break the queue's order: such a node covers nothing
  };
  // Largest pixel scale first; among equals the lower index, so that the cut is deterministic.
  using Entry = std::pair<double, uint32_t>;
  const auto before = [](const Entry& a, const Entry& b) {
    return a.first < b.first || (a.first == b.first && a.second > b.second);
  };
  std::priority_queue<Entry, std::vector<Entry>, decltype(before)> frontier(before);
  LodTreeCut cut;
  cut.over_budget = splat_budget < 1;
  frontier.push({pixel_scale(0), 0});
  uint64_t drawn = 1;
  while (!frontier.empty()) {
    const auto [scale, node] = frontier.top();
    const uint32_t children = file.child_count(node);
    if (children == 0) {
      cut.nodes.push_back(node);
      frontier.pop();
      continue;
    }
    if (drawn - 1 + children > splat_budget) break;
    frontier.pop();
    for (uint32_t c = 0; c < children; ++c) frontier.push({pixel_scale(file.child_start(node) + c), file.child_start(node) + c});
    drawn += children - 1;
  }
  for (; !frontier.empty(); frontier.pop()) cut.nodes.push_back(frontier.top().second);
  std::sort(cut.nodes.begin(), cut.nodes.end());
  return cut;
}

GaussianScene SplatLodTree::load(std::span<const uint32_t> nodes, const LoadOptions& options) const {
  for (uint32_t node : nodes) checked(impl_->file, impl_->name, node);
  GaussianScene scene = impl_->file.decode(nodes);
  detail::finish_scene(scene, impl_->name, options, "rad", "1", nullptr);
  return scene;
}

GaussianScene SplatLodTree::load_level(int level, const LoadOptions& options) const {
  return load(level_nodes(level), options);
}

bool is_lod_tree(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[8];
  if (!in.read(reinterpret_cast<char*>(head), 8)) return false;
  if (!detail::is_rad(std::as_bytes(std::span(head)))) return false;
  const uint32_t length = detail::load_le<uint32_t>(head + 4);
  if (length > (16u << 20)) return false;
  std::string text(length, '\0');
  if (!in.read(text.data(), length)) return false;
  const nlohmann::json meta = nlohmann::json::parse(text, nullptr, false);
  return meta.is_object() && meta.contains("lodTree") && meta["lodTree"] == true;
}

}  // namespace tilesplat
