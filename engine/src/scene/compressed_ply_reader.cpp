// Reader for PlayCanvas compressed PLY files (as SuperSplat and splat-transform write them).
//
// Layout: element 'chunk' (one per 256 Gaussians) of float bounds min_x..max_z and
// min_scale_x..max_scale_z, optionally min_r..max_b; element 'vertex' of four uint32 fields:
//   packed_position  11-10-11 bits of x y z, a fraction of the chunk's [min, max]
//   packed_rotation  2 bits: which component is largest, then 3 x 10 bits of the other three
//                    (w x y z order, skipping the largest), each in [-1/sqrt2, 1/sqrt2]
//   packed_scale     11-10-11 bits of the log scales over the chunk's [min_scale, max_scale]
//   packed_color     8-8-8-8 bits r g b (over the chunk's colour bounds when present) and opacity
// and an optional element 'sh' of uint8 f_rest_0..f_rest_{N-1} (channel-major), value
// (byte + 0.5) / 256 mapped to [-4, 4], 0 and 255 to the ends. Colours are display colours
// (0.5 + SH_C0 * dc), so dc = (colour - 0.5) / SH_C0.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <string_view>

#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

namespace tilesplat::detail {
namespace {

constexpr size_t kChunkSize = 256;

const PlyElement* find_element(const PlyHeader& header, std::string_view name) {
  for (const PlyElement& element : header.elements)
    if (element.name == name) return &element;
  return nullptr;
}

const PlyProperty* find_property(const PlyElement& element, std::string_view name) {
  for (const PlyProperty& property : element.properties)
    if (property.name == name) return &property;
  return nullptr;
}

constexpr std::array<std::string_view, 12> kChunkBounds = {
    "min_x",       "min_y",       "min_z",       "max_x",       "max_y",       "max_z",
    "min_scale_x", "min_scale_y", "min_scale_z", "max_scale_x", "max_scale_y", "max_scale_z"};
constexpr std::array<std::string_view, 6> kChunkColours = {"min_r", "min_g", "min_b",
                                                           "max_r", "max_g", "max_b"};
constexpr std::array<std::string_view, 4> kPacked = {"packed_position", "packed_rotation", "packed_scale",
                                                     "packed_color"};

double unorm(uint32_t value, int bits) {
  const uint32_t mask = (1u << bits) - 1u;
  return static_cast<double>(value & mask) / static_cast<double>(mask);
}

double lerp(float a, float b, double t) {
  return static_cast<double>(a) * (1.0 - t) + static_cast<double>(b) * t;
}

// A property's value in row `row` of an element of fixed-size rows starting at `base`.
template <typename T>
T field(const unsigned char* base, const PlyElement& element, const PlyProperty& property, size_t row) {
  return load_le<T>(base + row * element.fixed_row_size + property.row_offset);
}

}  // namespace

bool is_compressed_ply(const PlyHeader& header) {
  const PlyElement* vertex = find_element(header, "vertex");
  return find_element(header, "chunk") != nullptr && vertex && find_property(*vertex, "packed_position");
}

GaussianScene read_compressed_ply(const PlyBytes& ply, const PlyHeader& header, const LoadOptions& options,
                                  LoadReport* report) {
  if (header.format != PlyFormat::kBinaryLittleEndian)
    ply.fail("a compressed PLY must be binary_little_endian, not " + header.format_name);
  const PlyElement& chunk = *find_element(header, "chunk");
  const PlyElement& vertex = *find_element(header, "vertex");
  const PlyElement* sh = find_element(header, "sh");

  // The schema, checked before any data is touched.
  const auto require = [&](const PlyElement& element, std::string_view name, ScalarType type,
                           const char* type_name) -> const PlyProperty& {
    const PlyProperty* property = find_property(element, name);
    if (!property)
      ply.fail("compressed PLY: element '" + element.name + "' lacks property '" + std::string(name) + "'");
    if (property->is_list || property->type != type)
      ply.fail("compressed PLY: property '" + std::string(name) + "' of element '" + element.name +
               "' must be " + type_name);
    return *property;
  };
  for (const PlyElement& element : header.elements) {
    if (element.name != "chunk" && element.name != "vertex" && element.name != "sh")
      ply.fail("compressed PLY: unexpected element '" + element.name + "'");
    if (element.has_list) ply.fail("compressed PLY: element '" + element.name + "' has a list property");
  }
  std::array<const PlyProperty*, 12> bounds{};
  for (size_t i = 0; i < kChunkBounds.size(); ++i)
    bounds[i] = &require(chunk, kChunkBounds[i], ScalarType::kFloat32, "float");
  const bool chunk_colours = find_property(chunk, "min_r") != nullptr;
  std::array<const PlyProperty*, 6> colours{};
  if (chunk_colours)
    for (size_t i = 0; i < kChunkColours.size(); ++i)
      colours[i] = &require(chunk, kChunkColours[i], ScalarType::kFloat32, "float");
  std::array<const PlyProperty*, 4> packed{};
  for (size_t i = 0; i < kPacked.size(); ++i)
    packed[i] = &require(vertex, kPacked[i], ScalarType::kUint32, "uint");

  const uint64_t count = vertex.count;
  if (chunk.count != (count + kChunkSize - 1) / kChunkSize)
    ply.fail("compressed PLY: " + std::to_string(chunk.count) + " chunks for " + std::to_string(count) +
             " Gaussians; expected " + std::to_string((count + kChunkSize - 1) / kChunkSize) + " (one per " +
             std::to_string(kChunkSize) + ")");
  int sh_degree = 0;
  std::vector<const PlyProperty*> rest;
  if (sh) {
    const size_t n = sh->properties.size();
    sh_degree = n == 9 ? 1 : n == 24 ? 2 : n == 45 ? 3 : -1;
    if (sh_degree < 0)
      ply.fail("compressed PLY: element 'sh' has " + std::to_string(n) + " properties; expected 9, 24 or 45");
    if (sh->count != count)
      ply.fail("compressed PLY: element 'sh' has " + std::to_string(sh->count) + " rows for " +
               std::to_string(count) + " Gaussians");
    for (size_t k = 0; k < n; ++k)
      rest.push_back(&require(*sh, "f_rest_" + std::to_string(k), ScalarType::kUint8, "uchar"));
  }

  // Where each element's rows start; every size is checked against the file before allocating.
  const bool swap = std::endian::native != std::endian::little;
  const unsigned char *chunk_rows = nullptr, *vertex_rows = nullptr, *sh_rows = nullptr;
  size_t offset = header.data_offset;
  for (const PlyElement& element : header.elements) {
    const unsigned char* start = ply.data() + offset;
    offset = ply.skip_binary_element(element, offset, swap);
    if (&element == &chunk) chunk_rows = start;
    if (&element == &vertex) vertex_rows = start;
    if (&element == sh) sh_rows = start;
  }
  if (offset != ply.size())
    ply.fail(std::to_string(ply.size() - offset) + " bytes of trailing data after the declared elements");

  GaussianScene scene;
  allocate_scene(scene, static_cast<size_t>(count), sh_degree);
  const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
  const size_t rest_per_channel = coefficients - 1;
  for (size_t i = 0; i < count; ++i) {
    const size_t c = i / kChunkSize;
    const auto bound = [&](size_t k) { return field<float>(chunk_rows, chunk, *bounds[k], c); };
    const uint32_t position = field<uint32_t>(vertex_rows, vertex, *packed[0], i);
    const uint32_t rotation = field<uint32_t>(vertex_rows, vertex, *packed[1], i);
    const uint32_t scale = field<uint32_t>(vertex_rows, vertex, *packed[2], i);
    const uint32_t colour = field<uint32_t>(vertex_rows, vertex, *packed[3], i);

    const double p[3] = {unorm(position >> 21, 11), unorm(position >> 11, 10), unorm(position, 11)};
    const double s[3] = {unorm(scale >> 21, 11), unorm(scale >> 11, 10), unorm(scale, 11)};
    for (size_t a = 0; a < 3; ++a) {
      scene.positions[3 * i + a] = to_float(lerp(bound(a), bound(3 + a), p[a]));
      scene.log_scales[3 * i + a] = to_float(lerp(bound(6 + a), bound(9 + a), s[a]));
    }

    // Smallest three: the stored components in w x y z order without the largest one.
    const double norm = 1.0 / (std::sqrt(2.0) * 0.5);
    const double small[3] = {(unorm(rotation >> 20, 10) - 0.5) * norm,
                             (unorm(rotation >> 10, 10) - 0.5) * norm, (unorm(rotation, 10) - 0.5) * norm};
    const double largest =
        std::sqrt(std::max(0.0, 1.0 - (small[0] * small[0] + small[1] * small[1] + small[2] * small[2])));
    const size_t which = rotation >> 30;
    float* q = scene.rotations.data() + 4 * i;
    for (size_t j = 0, k = 0; j < 4; ++j) q[j] = static_cast<float>(j == which ? largest : small[k++]);

    const double rgb[3] = {unorm(colour >> 24, 8), unorm(colour >> 16, 8), unorm(colour >> 8, 8)};
    float* out = scene.sh.data() + 3 * coefficients * i;
    for (size_t ch = 0; ch < 3; ++ch) {
      const double value = chunk_colours ? lerp(field<float>(chunk_rows, chunk, *colours[ch], c),
                                                field<float>(chunk_rows, chunk, *colours[3 + ch], c), rgb[ch])
                                         : rgb[ch];
      out[ch] = to_float((value - 0.5) / kShC0);
    }
    const double alpha = std::clamp(unorm(colour, 8), 1e-6, 1.0 - 1e-6);
    scene.opacity_logits[i] = static_cast<float>(-std::log(1.0 / alpha - 1.0));

    for (size_t k = 0; k < rest.size(); ++k) {
      const uint8_t byte = field<uint8_t>(sh_rows, *sh, *rest[k], i);
      const double unit = byte == 0 ? 0.0 : byte == 255 ? 1.0 : (byte + 0.5) / 256.0;
      const size_t channel = k / rest_per_channel;
      const size_t coefficient = k % rest_per_channel + 1;
      out[3 * coefficient + channel] = static_cast<float>((unit - 0.5) * 8.0);
    }
  }
  finish_scene(scene, ply.name(), options, "compressed ply", "", report);
  return scene;
}

}  // namespace tilesplat::detail
