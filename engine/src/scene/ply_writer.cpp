// write_ply (tilesplat/scene.h): a scene as the 3DGS trainer writes its point cloud, the PLY every viewer
// reads. Every value is the scene's float as it is, so load_ply gives each one back to the bit.
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/image.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

void check_arrays(const GaussianScene& scene, const std::filesystem::path& path) {
  const size_t n = scene.size();
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument("write_ply: cannot write '" + path.string() + "': " + why);
  };
  if (scene.sh_degree < 0 || scene.sh_degree > 3)
    fail("sh_degree must be 0..3, got " + std::to_string(scene.sh_degree));
  if (scene.positions.size() != 3 * n || scene.log_scales.size() != 3 * n ||
      scene.rotations.size() != 4 * n || scene.sh.size() != n * size_t(scene.sh_coefficients()) * 3)
    fail("the scene's arrays have inconsistent sizes for " + std::to_string(n) + " Gaussians");
  if (scene.has_normals() && scene.normals.size() != 3 * n)
    fail("the scene's normals are not 3 per Gaussian");
}

// Appends the float in little-endian byte order.
void append(std::string& out, float value) {
  uint32_t bits = std::bit_cast<uint32_t>(value);
  if constexpr (std::endian::native == std::endian::big)
    bits = (bits >> 24) | ((bits >> 8) & 0xff00u) | ((bits << 8) & 0xff0000u) | (bits << 24);
  char bytes[4];
  std::memcpy(bytes, &bits, 4);
  out.append(bytes, 4);
}

}  // namespace

void write_ply(const GaussianScene& scene, const std::filesystem::path& path) {
  check_arrays(scene, path);
  const size_t n = scene.size();
  const size_t coefficients = size_t(scene.sh_coefficients());
  const size_t rest = coefficients - 1;  // per channel
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by tilesplat\nelement vertex " +
                       std::to_string(n) + "\n";
  auto property = [&header](const std::string& name) { header += "property float " + name + "\n"; };
  for (const char* name : {"x", "y", "z"}) property(name);
  if (scene.has_normals())
    for (const char* name : {"nx", "ny", "nz"}) property(name);
  for (int c = 0; c < 3; ++c) property("f_dc_" + std::to_string(c));
  for (size_t k = 0; k < 3 * rest; ++k) property("f_rest_" + std::to_string(k));
  property("opacity");
  for (int k = 0; k < 3; ++k) property("scale_" + std::to_string(k));
  for (int k = 0; k < 4; ++k) property("rot_" + std::to_string(k));
  header += "end_header\n";

  const size_t floats = 3 + (scene.has_normals() ? 3 : 0) + 3 * coefficients + 1 + 3 + 4;
  std::string out = header;
  out.reserve(header.size() + n * floats * 4);
  for (size_t i = 0; i < n; ++i) {
    for (size_t k = 0; k < 3; ++k) append(out, scene.positions[3 * i + k]);
    if (scene.has_normals())
      for (size_t k = 0; k < 3; ++k) append(out, scene.normals[3 * i + k]);
    const float* sh = &scene.sh[i * coefficients * 3];
    for (size_t c = 0; c < 3; ++c) append(out, sh[c]);
    // The trainer's f_rest is channel-major: red's coefficients 1..K-1, then green's, then blue's.
    for (size_t c = 0; c < 3; ++c)
      for (size_t k = 1; k < coefficients; ++k) append(out, sh[k * 3 + c]);
    append(out, scene.opacity_logits[i]);
    for (size_t k = 0; k < 3; ++k) append(out, scene.log_scales[3 * i + k]);
    for (size_t k = 0; k < 4; ++k) append(out, scene.rotations[4 * i + k]);
  }
  write_file_atomically(path, out);
}

}  // namespace tilesplat
