// libFuzzer harness for the SOG reader on a bundled .sog zip, and for the texels a SceneInParts holds for a
// SOG (detail::SogPartRows over detail::SogPacked, the decoder read_sog_zip runs on the whole file). The
// checks are fuzz_checks.h's check_reader, and: read in parts, the input is refused exactly when read_sog_zip
// refuses it, and its Gaussians (those with non-finite values dropped, as read_sog_zip drops them, each
// decoded from the texels alone) and report are read_sog_zip's, bit for bit. See tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "fuzz_checks.h"
#include "scene/part_rows.h"
#include "scene/scene_readers.h"
#include "scene/sog_packed.h"

namespace {

void check_in_parts(const uint8_t* data, size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  std::optional<tilesplat::GaussianScene> whole;
  tilesplat::LoadReport whole_report;
  try {
    whole = tilesplat::detail::read_sog_zip(bytes, "fuzz-input.sog", {}, &whole_report);
  } catch (const tilesplat::SceneError&) {
  }
  try {
    tilesplat::LoadReport report;
    const tilesplat::detail::SogPartRows rows(tilesplat::detail::SogPacked::from_zip(bytes, "fuzz-input.sog"),
                                              "fuzz-input.sog", {}, &report);
    FUZZ_CHECK(whole.has_value());
    FUZZ_CHECK(rows.size() == whole->size());
    FUZZ_CHECK(report.dropped == whole_report.dropped);
    FUZZ_CHECK(report.gaussians_in_file == whole_report.gaussians_in_file);
    tilesplat::fuzz::check_same_gaussians(rows.load(), *whole);
  } catch (const tilesplat::SceneError&) {
    FUZZ_CHECK(!whole.has_value());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check_in_parts(data, size);
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input",
                                       [](auto bytes, auto name, const auto& options, auto* report) {
                                         return tilesplat::detail::read_sog_zip(bytes, name, options, report);
                                       });
}
