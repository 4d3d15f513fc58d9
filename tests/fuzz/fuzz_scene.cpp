// libFuzzer harness for one of the compressed and interchange scene readers, chosen at compile time
// by TILESPLAT_FUZZ_READER (CMakeLists.txt builds one fuzzer per reader): splat, spz, sog (a zip),
// compressed_ply (through parse_ply) and gltf (.glb or .gltf with data: buffers).
//
// Every input must load or throw a SceneError that names the file; anything else (another
// exception, a sanitizer report, a timeout, more memory than -rss_limit_mb) is a finding. A loaded
// scene must be well-formed (fuzz_checks.h), and strict mode must fail exactly when the default
// mode drops a Gaussian. See tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "fuzz_checks.h"
#include "scene/scene_readers.h"
#include "tilesplat/scene.h"

namespace {

#define TILESPLAT_READER_splat 1
#define TILESPLAT_READER_spz 2
#define TILESPLAT_READER_sog 3
#define TILESPLAT_READER_compressed_ply 4
#define TILESPLAT_READER_gltf 5
#define TILESPLAT_READER_ID(reader) TILESPLAT_READER_ID_(reader)
#define TILESPLAT_READER_ID_(reader) TILESPLAT_READER_##reader

constexpr const char* kName = "fuzz-input";

tilesplat::GaussianScene read(std::span<const std::byte> bytes, const tilesplat::LoadOptions& options,
                              tilesplat::LoadReport* report) {
  namespace detail = tilesplat::detail;
#if TILESPLAT_READER_ID(TILESPLAT_FUZZ_READER) == TILESPLAT_READER_splat
  return detail::read_splat(bytes, kName, options, report);
#elif TILESPLAT_READER_ID(TILESPLAT_FUZZ_READER) == TILESPLAT_READER_spz
  return detail::read_spz(bytes, kName, options, report);
#elif TILESPLAT_READER_ID(TILESPLAT_FUZZ_READER) == TILESPLAT_READER_sog
  return detail::read_sog_zip(bytes, kName, options, report);
#elif TILESPLAT_READER_ID(TILESPLAT_FUZZ_READER) == TILESPLAT_READER_compressed_ply
  return tilesplat::parse_ply(bytes, kName, options, report);
#elif TILESPLAT_READER_ID(TILESPLAT_FUZZ_READER) == TILESPLAT_READER_gltf
  return detail::read_gltf(bytes, kName, nullptr, options, report);
#else
#error "TILESPLAT_FUZZ_READER must name a reader"
#endif
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  bool loaded = false;
  tilesplat::GaussianScene scene;
  tilesplat::LoadReport report;
  try {
    scene = read(bytes, {}, &report);
    loaded = true;
  } catch (const tilesplat::SceneError& error) {
    FUZZ_CHECK(std::string(error.what()).starts_with(std::string(kName) + ": "));
  }
  if (loaded) tilesplat::fuzz::check_scene(scene, report);

  tilesplat::LoadOptions strict;
  strict.strict = true;
  try {
    const tilesplat::GaussianScene strict_scene = read(bytes, strict, nullptr);
    FUZZ_CHECK(loaded && report.dropped == 0);
    FUZZ_CHECK(strict_scene.size() == scene.size() && strict_scene.positions == scene.positions);
  } catch (const tilesplat::SceneError&) {
    FUZZ_CHECK(!loaded || report.dropped > 0);
  }
  return 0;
}
