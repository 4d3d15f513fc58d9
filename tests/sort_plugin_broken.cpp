// Sort plugins that load but are not usable, for the loader's error tests: without
// TILESPLAT_TEST_PLUGIN_HAS_ENTRY it exports no entry function; with it, the entry registers nothing.
#include "tilesplat/sort_strategy.h"

#ifdef TILESPLAT_TEST_PLUGIN_HAS_ENTRY
extern "C" __attribute__((visibility("default"))) void tilesplat_sort_plugin_v1(
    tilesplat::SortPluginRegistry&) {}
#else
extern "C" __attribute__((visibility("default"))) int tilesplat_some_other_function() {
  return 1;
}
#endif
