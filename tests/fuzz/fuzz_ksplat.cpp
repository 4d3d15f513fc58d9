// libFuzzer harness for the GaussianSplats3D .ksplat reader, and for the layout a SceneInParts decodes a
// .ksplat's parts from (detail::KsplatPacked, the decoder read_ksplat runs on the whole file). The checks
// are fuzz_checks.h's check_reader, and: the layout is refused exactly when read_ksplat refuses the file,
// and any part of it, decoded as the renderer's parts decode it, is read_ksplat's Gaussians, bit for bit
// (where read_ksplat dropped none for non-finite values, which renumbers the rest). See tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "fuzz_checks.h"
#include "scene/ksplat_packed.h"
#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

namespace {

bool same_floats(const float* a, const float* b, size_t count) {
  return count == 0 || std::memcmp(a, b, count * sizeof(float)) == 0;
}

void check_packed(const uint8_t* data, size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  std::optional<tilesplat::GaussianScene> whole;
  try {
    whole = tilesplat::detail::read_ksplat(bytes, "fuzz-input.ksplat", {}, nullptr);
  } catch (const tilesplat::SceneError&) {
  }
  try {
    const tilesplat::detail::KsplatPacked packed(bytes, "fuzz-input.ksplat");
    FUZZ_CHECK(whole.has_value());
    FUZZ_CHECK(packed.size() >= whole->size());
    if (packed.size() != whole->size()) return;  // some dropped: PartRows renumbers, as tested in the suite
    std::vector<uint32_t> part;  // every other Gaussian, as a part gathers them
    for (size_t i = 1; i < packed.size(); i += 2) part.push_back(uint32_t(i));
    tilesplat::GaussianScene decoded = packed.decode(part);
    tilesplat::detail::normalize_rotations(decoded);  // finish_scene's, as KsplatPartRows::decode does
    const size_t sh = 3 * size_t(whole->sh_coefficients());
    for (size_t k = 0; k < part.size(); ++k) {
      const size_t i = part[k];
      FUZZ_CHECK(same_floats(&decoded.positions[3 * k], &whole->positions[3 * i], 3));
      FUZZ_CHECK(same_floats(&decoded.log_scales[3 * k], &whole->log_scales[3 * i], 3));
      FUZZ_CHECK(same_floats(&decoded.rotations[4 * k], &whole->rotations[4 * i], 4));
      FUZZ_CHECK(same_floats(&decoded.opacity_logits[k], &whole->opacity_logits[i], 1));
      FUZZ_CHECK(same_floats(&decoded.sh[sh * k], &whole->sh[sh * i], sh));
    }
  } catch (const tilesplat::SceneError&) {
    FUZZ_CHECK(!whole.has_value());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check_packed(data, size);
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input",
                                       [](auto bytes, auto name, const auto& options, auto* report) {
                                         return tilesplat::detail::read_ksplat(bytes, name, options, report);
                                       });
}
