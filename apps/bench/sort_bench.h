// The sort micro-benchmark (--sort-bench): keys per second against key count, per strategy and key
// width, with the CPU sorts measured in the same run so that every figure is also a ratio on this machine.
#pragma once

#include "bench_options.h"

namespace tilesplat::bench {

// Returns the exit code.
int run_sort_bench(const BenchOptions& options);

}  // namespace tilesplat::bench
