// serial-radix as a sort plugin: `tilesplat-bench --sort-plugin libserial_radix_sort.so --sort
// radix,serial-radix ...` times it beside the built-in strategies and compares their images.
// The plugin links no tilesplat symbol: everything it uses of tilesplat/sort_strategy.h is inline.
#include <memory>

#include "serial_radix_sort.h"

extern "C" __attribute__((visibility("default"))) void tilesplat_sort_plugin_v1(
    tilesplat::SortPluginRegistry& registry) {
  registry.add(SerialRadixSort::kName,
               [](const tilesplat::SortDevice& device) { return std::make_unique<SerialRadixSort>(device); });
}
