// tilesplat-bench: times the renderer's passes over repeated frames, per scene, image size, camera
// and sort strategy; or, with --sort-bench, the sort strategies alone on random keys against CPU
// sorts on the same keys; or one of the reports (--accuracy, --effects, --formats, --scaling).
#include "bench_options.h"
#include "cli.h"
#include "frame_bench.h"
#include "report_runs.h"
#include "sort_bench.h"

namespace {

namespace cli = tilesplat::cli;
using namespace tilesplat::bench;

int run(int argc, char** argv) {
  cli::load_sort_plugins(argc, argv);  // before the parser lists and checks the sort names
  BenchOptions options;
  cli::ArgParser parser(kProgram, kUsage, kDescription);
  add_bench_options(parser, options);
  if (cli::parse_and_handle_info_flags(parser, argc, argv, options.common)) return cli::kExitOk;
  options.command = cli::command_line(kProgram, argc, argv);
  check_bench_flags(parser, options);
  if (options.sort_bench) return run_sort_bench(options);
  if (options.accuracy) return run_accuracy_report(options);
  if (options.effects) return run_effects_report(options);
  if (options.formats) return run_formats_report(options);
  if (options.scaling) return run_scaling_report(options);
  if (!options.lod_budgets.empty()) return run_lod_report(options);
  if (options.sample_curve) return run_sample_curve(options);
  return run_frame_bench(options);
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
