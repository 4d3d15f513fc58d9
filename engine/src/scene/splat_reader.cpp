// Reader for antimatter15 .splat files, the format of the first web viewers.
//
// No header: 32 bytes a Gaussian, little-endian. float32 x y z; float32 linear scales x y z; uint8
// display colour r g b and opacity a (0.5 + SH_C0 * dc and sigmoid(logit), both times 255); uint8
// quaternion w x y z as (q + 1) * 255 / 2. No SH beyond the DC term.
#include <cmath>
#include <string>

#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

namespace tilesplat::detail {
namespace {

constexpr size_t kBytesPerGaussian = 32;

}  // namespace

GaussianScene read_splat(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                         LoadReport* report) {
  if (data.empty()) fail(name, "empty file, not a .splat file");
  if (data.size() % kBytesPerGaussian != 0)
    fail(name,
         "not a .splat file: its size (" + std::to_string(data.size()) +
             " bytes) is not a multiple of 32 bytes a Gaussian; the file is truncated or of another format");
  const size_t count = data.size() / kBytesPerGaussian;
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());

  GaussianScene scene;
  allocate_scene(scene, count, 0);
  for (size_t i = 0; i < count; ++i) {
    const unsigned char* record = bytes + i * kBytesPerGaussian;
    for (size_t a = 0; a < 3; ++a) {
      scene.positions[3 * i + a] = load_le<float>(record + 4 * a);
      // log(0) is -inf and a negative scale NaN: finish_scene drops such Gaussians.
      scene.log_scales[3 * i + a] =
          to_float(std::log(static_cast<double>(load_le<float>(record + 12 + 4 * a))));
      scene.sh[3 * i + a] = dc_of_colour_byte(record[24 + a]);
    }
    scene.opacity_logits[i] = static_cast<float>(clamped_logit(record[27] / 255.0));
    for (size_t j = 0; j < 4; ++j)
      scene.rotations[4 * i + j] = static_cast<float>(record[28 + j] / 255.0 * 2.0 - 1.0);
  }
  finish_scene(scene, name, options, "splat", "", report);
  return scene;
}

}  // namespace tilesplat::detail
