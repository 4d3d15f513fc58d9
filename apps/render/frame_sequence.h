// Rendering many frames in one run: which views (--views), which file each frame goes to
// (printf-style patterns, "out/view_%04d.exr"), and which frames this process renders when the
// work is split into shards (--shard I/N, Slurm job arrays, Kubernetes Indexed Jobs).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tilesplat::cli {

// "all", a comma list of indices and ranges ("0,3,8-11"), or "every:K" (0, K, 2K, ..., the
// evaluation split of the 3DGS papers with K = 8), over views 0 to view_count - 1. The order is
// the list's; an index past the end, a reversed range or an index named twice throws UsageError
// naming the flag, the index and the count.
std::vector<int> parse_view_selection(std::string_view flag, std::string_view text, int view_count);

// Whether the pattern has a frame-number conversion: %d, or %0Nd with a width N up to 9.
bool has_frame_number(std::string_view pattern);
// The pattern with its conversion replaced by `number` ("%%" is a literal percent sign); a pattern
// without a conversion is returned as it is. Throws UsageError naming `flag` for any other
// conversion, or for more than one.
std::string frame_file(std::string_view flag, std::string_view pattern, int number);

// Which slice of the frames this process renders: frames k with k mod count == index.
struct Shard {
  int index = 0;
  int count = 1;
  std::string source;  // how it was chosen: "--shard", "SLURM_ARRAY_TASK_ID=2", "JOB_COMPLETION_INDEX=1"
  bool takes(int frame) const { return frame % count == index; }
};

// The shard: --shard I/N when given (shard_flag), else a Slurm job array (SLURM_ARRAY_TASK_ID
// minus SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT), else a Kubernetes Indexed Job
// (JOB_COMPLETION_INDEX of --shard-count, else TILESPLAT_SHARD_COUNT), else the whole run as one
// shard. `environment` looks variables up (std::getenv in the app; a map in the tests). Throws
// UsageError for an index out of range, a count below 1, or an Indexed Job without its count.
Shard resolve_shard(const std::optional<std::string>& shard_flag, std::optional<int> shard_count_flag,
                    const std::function<std::optional<std::string>(const char*)>& environment);

}  // namespace tilesplat::cli
