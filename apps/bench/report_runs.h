// The bench's reports, each a run of its own: --accuracy (what each accuracy mode costs against the
// float64 reference), --effects (what each scene effect costs), --scaling (how time and memory grow)
// --formats (what each file format costs against the lossless PLY), --lod-curve (a LOD set's levels
// and splat budgets against its finest level) and --sample-curve (an averaged effect's sample counts
// against error and time). Each returns the exit code.
#pragma once

#include "bench_options.h"

namespace tilesplat::bench {

int run_accuracy_report(const BenchOptions& options);
int run_effects_report(const BenchOptions& options);
int run_scaling_report(const BenchOptions& options);
int run_formats_report(const BenchOptions& options);
int run_lod_report(const BenchOptions& options);
int run_sample_curve(const BenchOptions& options);

}  // namespace tilesplat::bench
