// tilesplat-info: what each scene file holds, in any format the engine reads: format and version,
// Gaussians and SH degree, size and bytes per Gaussian, boxes, opacity and scale ranges, what was
// dropped for non-finite values, and what loading it cost (time and peak memory).
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "info_options.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/lod_tree.h"
#include "tilesplat/scene.h"

namespace {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;

using namespace tilesplat::info;

// A .rad LOD tree's splats and each level's size (level 0 the leaves).
struct LodTreeLevels {
  size_t splats = 0;
  std::vector<size_t> level_sizes;
};

struct FileInfo {
  cli::LoadedScene loaded;
  uint64_t file_bytes = 0;
  uint64_t peak_bytes = 0;  // peak resident memory while loading, above what was resident before
  tilesplat::SceneStatistics stats;
  std::optional<LodTreeLevels> lod_tree;  // for a .rad with a LOD tree
};

// A file's size; a folder's (an unbundled SOG's meta.json brings its images) counts them all, and a LOD
// set's index its chunk files.
uint64_t file_bytes(const fs::path& path, const tilesplat::LodSet* lod_set = nullptr) {
  std::error_code ec;
  uint64_t bytes = fs::file_size(path, ec);
  if (ec) return 0;
  if (path.filename() == "meta.json")
    for (const auto& entry : fs::directory_iterator(path.parent_path(), ec))
      if (entry.is_regular_file() && entry.path().extension() == ".webp") bytes += entry.file_size();
  if (lod_set) {
    std::vector<std::string> files = lod_set->files();
    if (lod_set->environment()) files.push_back(*lod_set->environment());
    for (const std::string& file : files) bytes += file_bytes(path.parent_path() / file);
  }
  return bytes;
}

// Per level of a LOD set: its Gaussians, the chunks that hold some and the files they are in.
struct LodLevel {
  uint64_t gaussians = 0;
  size_t chunks = 0;
  size_t files = 0;
};

std::vector<LodLevel> lod_levels(const tilesplat::LodSet& set) {
  std::vector<LodLevel> levels(size_t(set.levels()));
  for (int level = 0; level < set.levels(); ++level) {
    std::vector<bool> used(set.files().size(), false);
    LodLevel& out = levels[size_t(level)];
    out.gaussians = set.level_size(level);
    for (const tilesplat::LodChunk& chunk : set.chunks()) {
      const tilesplat::LodSlice& slice = chunk.levels[size_t(level)];
      if (slice.count == 0) continue;
      ++out.chunks;
      if (!used[slice.file]) ++out.files;
      used[slice.file] = true;
    }
  }
  return levels;
}

FileInfo inspect(const std::string& file, bool strict) {
  FileInfo info;
  cli::reset_peak_memory();
  const uint64_t before = cli::resident_memory_bytes();
  info.loaded = cli::load_scene_file(file, strict, kProgram);
  const uint64_t peak = cli::peak_memory_bytes();
  info.peak_bytes = peak > before ? peak - before : 0;
  info.file_bytes = file_bytes(file, info.loaded.lod ? info.loaded.lod->set.get() : nullptr);
  info.stats = tilesplat::compute_statistics(info.loaded.scene);
  if (tilesplat::is_lod_tree(file)) {
    const tilesplat::SplatLodTree tree = tilesplat::SplatLodTree::open(file);
    LodTreeLevels levels{.splats = tree.nodes()};
    for (int level = 0; level < tree.levels(); ++level) levels.level_sizes.push_back(tree.level_nodes(level).size());
    info.lod_tree = std::move(levels);
  }
  return info;
}

std::string box(const double* low, const double* high) {
  char text[160];
  std::snprintf(text, sizeof text, "x [%.4g, %.4g]  y [%.4g, %.4g]  z [%.4g, %.4g]", low[0], high[0], low[1],
                high[1], low[2], high[2]);
  return text;
}

double megabytes(uint64_t bytes) {
  return static_cast<double>(bytes) / 1e6;
}

void print_text(const FileInfo& info) {
  const auto& loaded = info.loaded;
  const size_t n = loaded.scene.size();
  std::printf("%s\n", loaded.path.string().c_str());
  std::string format = loaded.report.format;
  if (!loaded.report.version.empty()) format += " version " + loaded.report.version;
  std::printf("  format       %s\n", format.c_str());
  std::printf("  gaussians    %s\n", cli::describe_scene(loaded.scene).c_str());
  std::printf("  file         %.3f MB, %.2f bytes per Gaussian\n", megabytes(info.file_bytes),
              n ? static_cast<double>(info.file_bytes) / static_cast<double>(n) : 0.0);
  if (n > 0) {
    std::printf("  box          %s\n", box(info.stats.min, info.stats.max).c_str());
    std::printf("  1-99%% box    %s\n", box(info.stats.robust_min, info.stats.robust_max).c_str());
    std::printf("  opacity      %.4g .. %.4g\n", info.stats.opacity_min, info.stats.opacity_max);
    std::printf("  scale        %.4g .. %.4g\n", info.stats.scale_min, info.stats.scale_max);
  }
  std::printf("  non-finite   %zu of %zu Gaussians dropped%s%s\n", loaded.report.dropped,
              loaded.report.gaussians_in_file, loaded.report.dropped ? ": " : "",
              loaded.report.summary().c_str());
  std::printf("  load         %.1f ms, peak memory +%.1f MB\n", loaded.load_ms, megabytes(info.peak_bytes));
  if (info.lod_tree) {
    const std::vector<size_t>& sizes = info.lod_tree->level_sizes;
    std::printf("  lod tree     %s splats, %zu levels (0: the leaves; %zu: the root)\n",
                cli::group_thousands(info.lod_tree->splats).c_str(), sizes.size(), sizes.size() - 1);
    for (size_t level = 0; level < sizes.size(); ++level)
      std::printf("  level %-6zu %s splats\n", level, cli::group_thousands(sizes[level]).c_str());
  }
  if (!loaded.lod) return;
  const tilesplat::LodSet& set = *loaded.lod->set;
  std::printf("  lod set      %d levels, %zu chunks, %zu chunk files%s%s\n", set.levels(),
              set.chunks().size(), set.files().size(), set.generator().empty() ? "" : ", made by ",
              set.generator().c_str());
  const std::vector<LodLevel> levels = lod_levels(set);
  for (size_t level = 0; level < levels.size(); ++level)
    std::printf("  level %-6zu %s Gaussians in %zu chunks, %zu files\n", level,
                cli::group_thousands(levels[level].gaussians).c_str(), levels[level].chunks,
                levels[level].files);
  if (set.environment())
    std::printf("  environment  %s, %s Gaussians, drawn with every level\n", set.environment()->c_str(),
                cli::group_thousands(set.environment_size()).c_str());
}

nlohmann::json to_json(const FileInfo& info) {
  const auto& loaded = info.loaded;
  const auto triple = [](const double* v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  nlohmann::json dropped = nlohmann::json::array();
  for (const auto& entry : loaded.report.dropped_by_property)
    dropped.push_back(
        {{"property", entry.property}, {"count", entry.count}, {"first_index", entry.first_index}});
  nlohmann::json out = {
      {"file", loaded.path.string()},
      {"format", loaded.report.format},
      {"version", loaded.report.version},
      {"gaussians", loaded.scene.size()},
      {"gaussians_in_file", loaded.report.gaussians_in_file},
      {"sh_degree", loaded.scene.sh_degree},
      {"file_bytes", info.file_bytes},
      {"bytes_per_gaussian", loaded.scene.empty() ? 0.0
                                                  : static_cast<double>(info.file_bytes) /
                                                        static_cast<double>(loaded.scene.size())},
      {"box_min", triple(info.stats.min)},
      {"box_max", triple(info.stats.max)},
      {"robust_box_min", triple(info.stats.robust_min)},
      {"robust_box_max", triple(info.stats.robust_max)},
      {"opacity_range", {info.stats.opacity_min, info.stats.opacity_max}},
      {"scale_range", {info.stats.scale_min, info.stats.scale_max}},
      {"non_finite_dropped", loaded.report.dropped},
      {"dropped_by_property", dropped},
      {"load_ms", loaded.load_ms},
      {"peak_memory_bytes", info.peak_bytes}};
  if (info.lod_tree) {
    out["lod_tree_splats"] = info.lod_tree->splats;
    out["lod_tree_levels"] = info.lod_tree->level_sizes;
  }
  if (loaded.lod) {
    const tilesplat::LodSet& set = *loaded.lod->set;
    nlohmann::json levels = nlohmann::json::array();
    for (const LodLevel& level : lod_levels(set))
      levels.push_back({{"gaussians", level.gaussians}, {"chunks", level.chunks}, {"files", level.files}});
    out["lod_levels"] = levels;
    out["lod_chunks"] = set.chunks().size();
    out["lod_files"] = set.files().size();
    out["lod_environment"] = set.environment() ? nlohmann::json(*set.environment()) : nlohmann::json();
  }
  return out;
}

int run(int argc, char** argv) {
  InfoOptions options;
  cli::ArgParser parser(kProgram, kUsage, kDescription);
  add_info_options(parser, options);
  if (cli::parse_and_handle_help(parser, argc, argv)) return cli::kExitOk;
  check_info_flags(options);
  const auto& files = options.files;
  const bool json = options.json;
  const bool strict = options.strict;
  nlohmann::json all = nlohmann::json::array();
  int status = cli::kExitOk;
  for (size_t i = 0; i < files.size(); ++i) {
    try {
      const FileInfo info = inspect(files[i], strict);
      if (json) {
        all.push_back(to_json(info));
      } else {
        if (i > 0) std::printf("\n");
        print_text(info);
      }
    } catch (const std::exception& error) {
      // One bad file does not hide the others; the exit status says something failed.
      cli::print_error(kProgram, cli::one_line(error.what()));
      status = cli::kExitFailure;
    }
  }
  if (json) std::printf("%s\n", all.dump(2).c_str());
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
