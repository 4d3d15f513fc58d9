#include "sort/sort_strategy.h"

#include <algorithm>
#include <functional>
#include <mutex>
#include <stdexcept>

#include "sort/bitonic_sort.h"
#include "sort/cpu_radix_strategy.h"
#include "sort/onesweep_sort.h"
#include "sort/radix_sort.h"
#include "sort/tile_local_sort.h"

namespace tilesplat {

namespace {

struct Registration {
  std::string name;
  bool exact;  // SortStrategy::exact(), known without a device (tests check that the two agree)
  SortStrategyMaker make;
};

// Guards registry(): strategies registered by a program or a plugin join the built-in ones while
// renderers on other threads may be looking names up.
std::mutex registry_mutex;

// The default first, then the other GPU sorts, then the host ones, then those registered at run time.
std::vector<Registration>& registry() {
  static std::vector<Registration> strategies = {
      {"radix", true, [](vk::Context& ctx) { return std::make_unique<RadixSort>(ctx); }},
      {"onesweep", true, [](vk::Context& ctx) { return std::make_unique<OnesweepSort>(ctx); }},
      {"bitonic", true, [](vk::Context& ctx) { return std::make_unique<BitonicSort>(ctx); }},
      {"tile-local", true, [](vk::Context& ctx) { return std::make_unique<TileLocalSort>(ctx); }},
      {"cpu-radix", true,
       [](vk::Context& ctx) { return std::make_unique<CpuRadixSort>(ctx, CpuRadixSort::Keys::kExact); }},
      {"cpu-radix16", false,
       [](vk::Context& ctx) {
         return std::make_unique<CpuRadixSort>(ctx, CpuRadixSort::Keys::kQuantized16);
       }},
  };
  return strategies;
}

const size_t kBuiltIn = registry().size();  // before anything is registered at run time

// A copy: the registry may grow (and move its entries) once the lock is released.
Registration find(const std::string& name) {
  const std::lock_guard lock(registry_mutex);
  for (const auto& r : registry())
    if (name == r.name) return r;
  std::string valid;
  for (const auto& r : registry()) valid += (valid.empty() ? "" : ", ") + r.name;
  throw std::invalid_argument("unknown sort strategy '" + name + "' (available: " + valid + ")");
}

}  // namespace

std::vector<std::string> available_sort_strategies() {
  const std::lock_guard lock(registry_mutex);
  std::vector<std::string> names;
  for (const auto& r : registry()) names.push_back(r.name);
  return names;
}

void add_sort_strategy(const std::string& name, bool exact, SortStrategyMaker make) {
  if (name.empty()) throw std::invalid_argument("a sort strategy needs a name");
  for (const char c : name)
    if (c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r')
      throw std::invalid_argument("sort strategy name '" + name +
                                  "' contains a comma or whitespace (names are listed comma-separated)");
  if (!make) throw std::invalid_argument("sort strategy '" + name + "' has no factory");
  const std::lock_guard lock(registry_mutex);
  for (const auto& r : registry())
    if (r.name == name)
      throw std::invalid_argument("a sort strategy named '" + name + "' is already registered");
  registry().push_back({name, exact, std::move(make)});
}

void remove_sort_strategy(const std::string& name) {
  const std::lock_guard lock(registry_mutex);
  std::vector<Registration>& strategies = registry();
  // The built-in ones are the first kBuiltIn entries: never removed.
  const auto first_added = strategies.begin() + std::ptrdiff_t(std::min(kBuiltIn, strategies.size()));
  strategies.erase(
      std::remove_if(first_added, strategies.end(), [&](const Registration& r) { return r.name == name; }),
      strategies.end());
}

std::unique_ptr<SortStrategy> make_sort_strategy(const std::string& name, vk::Context& ctx) {
  return find(name).make(ctx);
}

bool sort_strategy_exact(const std::string& name) { return find(name).exact; }

}  // namespace tilesplat
