#include "sort/sort_strategy.h"

#include <functional>
#include <stdexcept>

#include "sort/bitonic_sort.h"
#include "sort/cpu_radix_strategy.h"
#include "sort/onesweep_sort.h"
#include "sort/radix_sort.h"
#include "sort/tile_local_sort.h"

namespace tilesplat {

namespace {

struct Registration {
  const char* name;
  bool exact;  // SortStrategy::exact(), known without a device (tests check that the two agree)
  std::function<std::unique_ptr<SortStrategy>(vk::Context&)> make;
};

// The default first, then the other GPU sorts, then the host ones.
const std::vector<Registration>& registry() {
  static const std::vector<Registration> strategies = {
      {"radix", true, [](vk::Context& ctx) { return std::make_unique<RadixSort>(ctx); }},
      {"onesweep", true, [](vk::Context& ctx) { return std::make_unique<OnesweepSort>(ctx); }},
      {"bitonic", true, [](vk::Context& ctx) { return std::make_unique<BitonicSort>(ctx); }},
      {"tile-local", true, [](vk::Context& ctx) { return std::make_unique<TileLocalSort>(ctx); }},
      {"cpu-radix", true,
       [](vk::Context& ctx) { return std::make_unique<CpuRadixSort>(ctx, CpuRadixSort::Keys::kExact); }},
      {"cpu-radix16", false,
       [](vk::Context& ctx) { return std::make_unique<CpuRadixSort>(ctx, CpuRadixSort::Keys::kQuantized16); }},
  };
  return strategies;
}

const Registration& find(const std::string& name) {
  for (const auto& r : registry())
    if (name == r.name) return r;
  std::string valid;
  for (const auto& r : registry()) valid += (valid.empty() ? "" : ", ") + std::string(r.name);
  throw std::invalid_argument("unknown sort strategy '" + name + "' (available: " + valid + ")");
}

}  // namespace

std::vector<std::string> available_sort_strategies() {
  std::vector<std::string> names;
  for (const auto& r : registry()) names.emplace_back(r.name);
  return names;
}

std::unique_ptr<SortStrategy> make_sort_strategy(const std::string& name, vk::Context& ctx) {
  return find(name).make(ctx);
}

bool sort_strategy_exact(const std::string& name) { return find(name).exact; }

}  // namespace tilesplat
