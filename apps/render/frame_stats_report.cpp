#include "frame_stats_report.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "cli.h"

namespace tilesplat::render_app {

namespace cli = tilesplat::cli;

void print_row(const std::string& name, const std::string& value, const std::string& unit) {
  if (unit.empty())
    std::printf("%-22s %14s\n", name.c_str(), value.c_str());
  else
    std::printf("%-22s %14s %s\n", name.c_str(), value.c_str(), unit.c_str());
}

void print_frame_stats(const tilesplat::FrameStats& stats, const tilesplat::DeviceInfo& device) {
  std::printf("device: %s (driver %s), subgroup size %u, largest allocation %s MiB, memory %s MiB\n",
              device.name.c_str(), device.driver.c_str(), device.subgroup_size,
              cli::format_fixed(double(device.max_allocation_size) / (1024.0 * 1024.0), 0).c_str(),
              cli::format_fixed(double(device.device_memory) / (1024.0 * 1024.0), 0).c_str());
  for (const auto& pass : stats.passes) print_row(pass.name, cli::format_fixed(pass.gpu_ms, 3), "ms");
  print_row("gpu frame", cli::format_fixed(stats.gpu_ms, 3), "ms");
  print_row("cpu frame", cli::format_fixed(stats.cpu_ms, 3), "ms");
  print_row("gaussians", std::to_string(stats.gaussians), "");
  print_row("visible", std::to_string(stats.visible), "");
  print_row("intersections", std::to_string(stats.intersections), "");
  print_row("sort", stats.sort_strategy, "");
  print_row("sort bits", std::to_string(stats.sort_bits), "");
  print_row("retries", std::to_string(stats.retries), "");
  auto mib = [](uint64_t bytes) { return cli::format_fixed(double(bytes) / (1024.0 * 1024.0), 2); };
  print_row("device memory", mib(stats.device_bytes), "MiB");
  print_row("peak device memory", mib(stats.peak_device_bytes), "MiB");
  print_row("scene parts", std::to_string(stats.scene_parts), "");
  print_row("depth order", cli::format_fixed(stats.depth_order_ms, 1), "ms");
  print_row("image bands", std::to_string(stats.image_bands), "");
  // Values stored as their type's largest finite value instead of an infinity (image.h, SaturatedValues).
  print_row("saturated values", std::to_string(stats.saturated.total()), "");
  for (const auto& [channel, count] : stats.saturated.channels)
    print_row("  saturated " + channel, std::to_string(count), "");
  print_row("peak resident memory", mib(cli::peak_memory_bytes()), "MiB");
}

void print_lod_selection(const tilesplat::LodSelection& selection) {
  int levels = 0;
  for (const int level : selection.chunk_levels) levels = std::max(levels, level + 1);
  std::vector<int> chunks(size_t(levels), 0);
  int culled = 0;
  for (const int level : selection.chunk_levels) level < 0 ? ++culled : ++chunks[size_t(level)];
  for (int level = 0; level < levels; ++level)
    print_row("lod " + std::to_string(level) + " chunks", std::to_string(chunks[size_t(level)]), "");
  print_row("lod chunks out of view", std::to_string(culled), "");
  print_row("lod splats", std::to_string(selection.splats), "");
  if (selection.over_budget)
    print_row("lod over budget", "yes",
              "(the coarsest levels in view need " + std::to_string(selection.coarsest_splats) + ")");
}

void print_lod_tree_cut(const tilesplat::SplatLodTree& tree, const std::vector<uint32_t>& cut) {
  size_t inner = 0;
  for (const uint32_t node : cut) inner += tree.child_count(node) > 0 ? 1 : 0;
  print_row("lod tree splats", std::to_string(cut.size()), "");
  print_row("lod tree inner nodes", std::to_string(inner), "(merged splats drawn for their leaves)");
}

}  // namespace tilesplat::render_app
