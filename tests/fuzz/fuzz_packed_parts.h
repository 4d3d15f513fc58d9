// The part-by-part check of the formats whose Gaussians decode one by one from a layout held apart
// (fuzz_spz.cpp, fuzz_ksplat.cpp). Engine-internal (scene/scene_reading.h), unlike fuzz_checks.h, which the
// gcc test program compiles too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "fuzz_checks.h"
#include "scene/scene_reading.h"

namespace tilesplat::fuzz {

// A format whose Gaussians decode one by one from a layout held apart (`Packed`: SpzPacked, KsplatPacked),
// as a scene read part by part decodes them: the layout is refused exactly when the whole read (`read_whole`)
// refuses the file, and every other Gaussian of it, with finish_scene's rotations, is the whole read's, bit
// for bit. `may_drop`: the whole read may drop Gaussians for non-finite values, which renumbers the rest
// (the suite checks those files through SceneInParts); the check is then left out.
template <typename Packed, typename ReadWhole>
void check_packed_parts(std::span<const std::byte> bytes, const char* name, bool may_drop, ReadWhole read_whole) {
  std::optional<tilesplat::GaussianScene> whole;
  try {
    whole = read_whole(bytes, name);
  } catch (const tilesplat::SceneError&) {
  }
  try {
    const Packed packed(bytes, name);
    FUZZ_CHECK(whole.has_value());
    FUZZ_CHECK(may_drop ? packed.size() >= whole->size() : packed.size() == whole->size());
    if (packed.size() != whole->size()) return;
    std::vector<uint32_t> part;
    for (size_t i = 1; i < packed.size(); i += 2) part.push_back(uint32_t(i));
    tilesplat::GaussianScene decoded = packed.decode(part);
    tilesplat::detail::normalize_rotations(decoded);
    check_same_gaussians(decoded, gaussians_at(*whole, part));
  } catch (const tilesplat::SceneError&) {
    FUZZ_CHECK(!whole.has_value());
  }
}

}  // namespace tilesplat::fuzz
