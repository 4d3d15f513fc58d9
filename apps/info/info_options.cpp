#include "info_options.h"

namespace tilesplat::info {

namespace cli = tilesplat::cli;

void add_info_options(cli::ArgParser& parser, InfoOptions& options) {
  parser.add_switch("--json", "one JSON array of objects on stdout, for scripts", &options.json);
  parser.add_switch("--strict", "fail on a non-finite value instead of dropping the Gaussian",
                    &options.strict);
  parser.add_positional_list("FILE", "scene files", &options.files);
}

void check_info_flags(const InfoOptions& options) {
  if (options.files.empty()) throw cli::UsageError("missing the FILE argument (see --help)");
}

}  // namespace tilesplat::info
