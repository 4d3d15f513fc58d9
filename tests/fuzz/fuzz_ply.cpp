// libFuzzer harness for the PLY reader (parse_ply, the in-memory core of load_ply), and for the rows a
// MappedPly reads part by part (detail::PlyRows, the same decoder reached another way).
//
// Every input must either load or throw SceneError: any other exception, a sanitizer report, a
// timeout or an allocation over -rss_limit_mb is a finding. A scene that loads must also be
// well-formed (consistent array sizes, finite values, unit quaternions), and the strict mode must
// agree with the default one. Rows read part by part must be refused or be parse_ply's Gaussians, bit
// for bit. See tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "fuzz_checks.h"
#include "scene/ply_rows.h"
#include "tilesplat/scene.h"

namespace {

// The rows every one, non-finite ones dropped, then gathered as a MappedPly gathers a part: parse_ply's
// scene, or a SceneError (PlyRows refuses ASCII and compressed PLYs, which parse_ply reads).
void check_rows(const uint8_t* data, size_t size) {
  std::optional<tilesplat::GaussianScene> whole;
  try {
    whole = tilesplat::parse_ply(std::as_bytes(std::span(data, size)), "fuzz-input.ply");
  } catch (const tilesplat::SceneError&) {
  }
  try {
    tilesplat::detail::PlyRows rows("fuzz-input.ply", data, size, {});
    tilesplat::GaussianScene block;
    std::vector<size_t> dropped;
    rows.decode_range(0, rows.rows(), block, dropped);
    std::vector<uint64_t> kept;
    for (size_t row = 0, next = 0; row < rows.rows(); ++row) {
      if (next < dropped.size() && dropped[next] == row) {
        ++next;
        continue;
      }
      kept.push_back(row);
    }
    const tilesplat::GaussianScene parts = rows.decode(kept);
    FUZZ_CHECK(whole.has_value());  // read part by part only what parse_ply reads
    tilesplat::fuzz::check_same_gaussians(parts, *whole);
  } catch (const tilesplat::SceneError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check_rows(data, size);
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input.ply",
                                       [](auto bytes, auto name, const auto& options, auto* report) {
                                         return tilesplat::parse_ply(bytes, name, options, report);
                                       });
}
