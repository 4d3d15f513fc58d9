// libFuzzer harness for the GaussianSplats3D .ksplat reader, and for the layout a SceneInParts decodes a
// .ksplat's parts from (detail::KsplatPacked, the decoder read_ksplat runs on the whole file). The checks
// are fuzz_checks.h's check_reader, and: the layout is refused exactly when read_ksplat refuses the file,
// and any part of it, decoded as the renderer's parts decode it, is read_ksplat's Gaussians, bit for bit
// (where read_ksplat dropped none for non-finite values, which renumbers the rest). See tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"
#include "fuzz_packed_parts.h"
#include "scene/ksplat_packed.h"
#include "scene/scene_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tilesplat::fuzz::check_packed_parts<tilesplat::detail::KsplatPacked>(
      std::as_bytes(std::span(data, size)), "fuzz-input.ksplat", /*may_drop=*/true,
      [](auto bytes, const char* name) { return tilesplat::detail::read_ksplat(bytes, name, {}, nullptr); });
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input",
                                       [](auto bytes, auto name, const auto& options, auto* report) {
                                         return tilesplat::detail::read_ksplat(bytes, name, options, report);
                                       });
}
