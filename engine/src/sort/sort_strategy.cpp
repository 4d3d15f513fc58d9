#include "sort/sort_strategy.h"

#include <algorithm>
#include <stdexcept>

#include "sort/bitonic_sort.h"
#include "sort/cpu_radix_strategy.h"
#include "sort/onesweep_sort.h"
#include "sort/radix_sort.h"
#include "sort/tile_local_sort.h"

namespace tilesplat {

std::vector<std::string> available_sort_strategies() {
  return {"radix", "bitonic", "cpu-radix", "cpu-radix16", "onesweep", "tile-local"};
}

std::unique_ptr<SortStrategy> make_sort_strategy(const std::string& name, vk::Context& ctx) {
  if (name == "radix") return std::make_unique<RadixSort>(ctx);
  if (name == "bitonic") return std::make_unique<BitonicSort>(ctx);
  if (name == "cpu-radix") return std::make_unique<CpuRadixSort>(ctx, CpuRadixSort::Keys::kExact);
  if (name == "cpu-radix16") return std::make_unique<CpuRadixSort>(ctx, CpuRadixSort::Keys::kQuantized16);
  if (name == "onesweep") return std::make_unique<OnesweepSort>(ctx);
  if (name == "tile-local") return std::make_unique<TileLocalSort>(ctx);
  std::string valid;
  for (const auto& n : available_sort_strategies()) valid += (valid.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown sort strategy '" + name + "' (available: " + valid + ")");
}

bool sort_strategy_exact(const std::string& name) {
  const auto names = available_sort_strategies();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string valid;
    for (const auto& n : names) valid += (valid.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown sort strategy '" + name + "' (available: " + valid + ")");
  }
  return name != "cpu-radix16";  // CpuRadixSort::exact(); the registry test checks that they agree
}

}  // namespace tilesplat
