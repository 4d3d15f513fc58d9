#include "frame_sequence.h"

#include <limits>
#include <set>

#include "cli.h"

namespace tilesplat::cli {
namespace {

// Built by appending: GCC 12 misreports '"\'" + text + "\'"' under -Wrestrict.
std::string in_quotes(std::string_view text) {
  std::string quoted(1, '\'');
  quoted.append(text);
  quoted += '\'';
  return quoted;
}

struct Conversion {
  size_t begin = 0, end = 0;  // [begin, end) of "%04d"
  int width = 0;
  bool zero_padded = false;
};

// The pattern's one frame-number conversion, if any.
std::optional<Conversion> find_conversion(std::string_view flag, std::string_view pattern) {
  std::optional<Conversion> found;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      ++i;
      continue;
    }
    Conversion conversion;
    conversion.begin = i;
    size_t j = i + 1;
    if (j < pattern.size() && pattern[j] == '0') {
      conversion.zero_padded = true;
      ++j;
    }
    if (j < pattern.size() && pattern[j] >= '1' && pattern[j] <= '9') conversion.width = pattern[j++] - '0';
    if (j >= pattern.size() || pattern[j] != 'd')
      throw UsageError(std::string(flag) + " " + in_quotes(pattern) +
                       ": a frame number is written %d or %0Nd (N = 1 to 9), and %% is a percent sign");
    conversion.end = j + 1;
    if (found)
      throw UsageError(std::string(flag) + " " + in_quotes(pattern) + " has more than one frame number");
    found = conversion;
    i = j;
  }
  return found;
}

}  // namespace

std::vector<int> parse_view_selection(std::string_view flag, std::string_view text, int view_count) {
  const std::string prefix = std::string(flag) + " " + in_quotes(text) + ": ";
  std::vector<int> views;
  if (text == "all") {
    for (int v = 0; v < view_count; ++v) views.push_back(v);
    return views;
  }
  if (text.starts_with("every:")) {
    const int step = parse_int(flag, text.substr(6), 1, std::numeric_limits<int>::max());
    for (int v = 0; v < view_count; v += step) {
      views.push_back(v);
      if (v > view_count - step) break;  // v + step would overflow or pass the end
    }
    return views;
  }
  auto index = [&](std::string_view number) {
    const int value = parse_int(flag, number, 0, std::numeric_limits<int>::max());
    if (value >= view_count)
      throw UsageError(prefix + "there is no view " + std::to_string(value) + ": the cameras have " +
                       std::to_string(view_count) + " (0 to " + std::to_string(view_count - 1) + ")");
    return value;
  };
  std::set<int> named;
  for (const std::string& item : split(text, ',')) {
    const size_t dash = item.find('-', 1);
    const int first = index(std::string_view(item).substr(0, dash));
    const int last = dash == std::string::npos ? first : index(std::string_view(item).substr(dash + 1));
    if (last < first) throw UsageError(prefix + "the range " + in_quotes(item) + " runs backwards");
    for (int v = first; v <= last; ++v) {
      if (!named.insert(v).second) throw UsageError(prefix + "view " + std::to_string(v) + " is named twice");
      views.push_back(v);
    }
  }
  if (views.empty()) throw UsageError(prefix + "names no views (use all, 0,3,8-11 or every:8)");
  return views;
}

bool has_frame_number(std::string_view pattern) {
  return find_conversion("-o", pattern).has_value();
}

std::string frame_file(std::string_view flag, std::string_view pattern, int number) {
  const auto conversion = find_conversion(flag, pattern);
  std::string file;
  std::string digits = std::to_string(number);
  if (conversion && static_cast<int>(digits.size()) < conversion->width)
    digits.insert(0, static_cast<size_t>(conversion->width) - digits.size(),
                  conversion->zero_padded ? '0' : ' ');
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (conversion && i == conversion->begin) {
      file += digits;
      i = conversion->end - 1;
    } else if (pattern[i] == '%' && i + 1 < pattern.size() && pattern[i + 1] == '%') {
      file += '%';
      ++i;
    } else {
      file += pattern[i];
    }
  }
  return file;
}

Shard resolve_shard(const std::optional<std::string>& shard_flag, std::optional<int> shard_count_flag,
                    const std::function<std::optional<std::string>(const char*)>& environment) {
  Shard shard;
  auto check = [&shard](const std::string& what) {
    if (shard.count < 1) throw UsageError(what + ": the shard count must be at least 1");
    if (shard.index < 0 || shard.index >= shard.count)
      throw UsageError(what + ": shard index " + std::to_string(shard.index) + " is out of range for " +
                       std::to_string(shard.count) + " shards (0 to " + std::to_string(shard.count - 1) +
                       ")");
  };
  constexpr int kMax = std::numeric_limits<int>::max();
  if (shard_flag) {
    const size_t slash = shard_flag->find('/');
    if (slash == std::string::npos)
      throw UsageError("--shard expects I/N (this process renders frames k with k mod N == I), got " +
                       in_quotes(*shard_flag));
    shard.index = parse_int("--shard", std::string_view(*shard_flag).substr(0, slash), 0, kMax);
    shard.count = parse_int("--shard", std::string_view(*shard_flag).substr(slash + 1), 1, kMax);
    shard.source = "--shard";
    check("--shard " + *shard_flag);
    return shard;
  }
  if (const auto task = environment("SLURM_ARRAY_TASK_ID")) {
    const auto count = environment("SLURM_ARRAY_TASK_COUNT");
    if (!count) throw UsageError("SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not");
    const int id = parse_int("SLURM_ARRAY_TASK_ID", *task, 0, kMax);
    const auto min = environment("SLURM_ARRAY_TASK_MIN");
    // Arrays may start anywhere (--array=1-4): the index counts from the first task.
    shard.index = id - (min ? parse_int("SLURM_ARRAY_TASK_MIN", *min, 0, kMax) : 0);
    shard.count = parse_int("SLURM_ARRAY_TASK_COUNT", *count, 1, kMax);
    shard.source = "SLURM_ARRAY_TASK_ID=" + *task;
    check("the Slurm array task " + *task + " (SLURM_ARRAY_TASK_MIN " + min.value_or("unset") + ", COUNT " +
          *count + ")");
    return shard;
  }
  if (const auto index = environment("JOB_COMPLETION_INDEX")) {
    std::optional<int> count = shard_count_flag;
    if (!count)
      if (const auto text = environment("TILESPLAT_SHARD_COUNT"))
        count = parse_int("TILESPLAT_SHARD_COUNT", *text, 1, kMax);
    if (!count)
      throw UsageError(
          "JOB_COMPLETION_INDEX is set (a Kubernetes Indexed Job) but not the number of shards: "
          "pass --shard-count N or set TILESPLAT_SHARD_COUNT to the Job's completions");
    shard.index = parse_int("JOB_COMPLETION_INDEX", *index, 0, kMax);
    shard.count = *count;
    shard.source = "JOB_COMPLETION_INDEX=" + *index;
    check("the Indexed Job's JOB_COMPLETION_INDEX " + *index);
    return shard;
  }
  return shard;
}

}  // namespace tilesplat::cli
