// libFuzzer harness for the Niantic .spz reader (versions 2-4), and for the packed Gaussians a SceneInParts
// holds for an SPZ (detail::SpzPacked, the decoder read_spz runs on the whole file). The checks are
// fuzz_checks.h's check_reader, and: the packed Gaussians are refused exactly when read_spz refuses them,
// and any part of them, decoded as the renderer's parts decode it, is read_spz's Gaussians, bit for bit.
// See tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"
#include "fuzz_packed_parts.h"
#include "scene/scene_readers.h"
#include "scene/spz_packed.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tilesplat::fuzz::check_packed_parts<tilesplat::detail::SpzPacked>(
      std::as_bytes(std::span(data, size)), "fuzz-input.spz", /*may_drop=*/false,
      [](auto bytes, const char* name) { return tilesplat::detail::read_spz(bytes, name, {}, nullptr); });
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input",
                                       [](auto bytes, auto name, const auto& options, auto* report) {
                                         return tilesplat::detail::read_spz(bytes, name, options, report);
                                       });
}
