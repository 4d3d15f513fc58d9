#include "sort/sort_strategy.h"

#include <stdexcept>

#include "sort/bitonic_sort.h"
#include "sort/radix_sort.h"

namespace tilesplat {

std::vector<std::string> available_sort_strategies() { return {"radix", "bitonic"}; }

std::unique_ptr<SortStrategy> make_sort_strategy(const std::string& name, vk::Context& ctx) {
  if (name == "radix") return std::make_unique<RadixSort>(ctx);
  if (name == "bitonic") return std::make_unique<BitonicSort>(ctx);
  std::string valid;
  for (const auto& n : available_sort_strategies()) valid += (valid.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown sort strategy '" + name + "' (available: " + valid + ")");
}

}  // namespace tilesplat
