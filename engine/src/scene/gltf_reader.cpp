// Reader for glTF 2.0 scenes with the KHR_gaussian_splatting extension (.glb and .gltf).
//
// Every mesh primitive that carries the extension, in the nodes of the default scene, is one set of
// Gaussians (a POINTS primitive). Attributes (the extension's text): POSITION, and with the prefix
// "KHR_gaussian_splatting:" ROTATION (unit quaternion x y z w), SCALE (linear), OPACITY (in [0, 1]),
// SH_DEGREE_0_COEF_0 and SH_DEGREE_l_COEF_n (l = 1..3, RGB each). ROTATION and SCALE may be
// normalized integers, OPACITY normalized unsigned ones. Values are activated in the file, so the
// reader takes log(scale) and logit(opacity) back to the trainer's parameters. colorSpace
// srgb_rec709_display is what trainers produce and the engine renders as it is.
//
// SPZ compression (Khronos drafts): the primitive's Gaussians are an SPZ stream in a bufferView instead of
// its accessors. The draft's current name, KHR_gaussian_splatting_compression_spz_2, and its earlier one
// without "_2" sit inside the primitive's KHR_gaussian_splatting extension; the first draft,
// KHR_spz_compression, sits on the primitive itself. Each names the bufferView; the accessors then only
// describe what the stream decodes to (their count must be its count). The stream is packed from glTF's
// axes (the drafts require SPZ's LUF option), so decoded to SPZ's own RUB it lands where any .spz does.
//
// Axes: glTF is y up; the engine keeps the trainer's y down. As splat-transform and the PlayCanvas
// engine do, the glTF scene is the trainer's turned 180 degrees about z, so x and y flip (positions,
// quaternions, and SH coefficients by their parity in x and y). Node transforms (matrix or TRS) are
// applied first; a node scale must be uniform, since Gaussians cannot be sheared.
#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scene/gltf_container.h"
#include "scene/scene_readers.h"
#include "scene/scene_reading.h"
#include "scene/spz_packed.h"
#include "tilesplat/scene_description.h"

namespace tilesplat::detail {
namespace {

using nlohmann::json;

constexpr std::string_view kPrefix = "KHR_gaussian_splatting:";
constexpr const char* kSplatting = "KHR_gaussian_splatting";
// The SPZ drafts: the two that extend KHR_gaussian_splatting, newest first, and the first, on the primitive.
constexpr const char* kSpzInSplatting[] = {"KHR_gaussian_splatting_compression_spz_2",
                                           "KHR_gaussian_splatting_compression_spz"};
constexpr const char* kSpzOnPrimitive = "KHR_spz_compression";
// Sign of each SH basis function (k = 1..15) when x and y flip: its parity in x and y, (-1)^k.
constexpr float kFlipSh[15] = {-1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1};

class GltfReader {
 public:
  GltfReader(std::string_view name, const FileLoader& load_buffer) : name_(name), load_buffer_(load_buffer) {}

  [[noreturn]] void fail(const std::string& what) const { detail::fail(name_, what); }

  GaussianScene read(std::span<const std::byte> data, std::string* format) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
    std::string_view json_text;
    if (data.size() >= 4 && load_le<uint32_t>(bytes) == kGlbMagic) {
      *format = "glb";
      const GlbChunks chunks = split_glb(name_, bytes, data.size());
      json_text = chunks.json;
      bin_ = chunks.bin;
    } else {
      *format = "gltf";
      json_text = std::string_view(reinterpret_cast<const char*>(bytes), data.size());
    }
    gltf_ = json::parse(json_text.begin(), json_text.end(), nullptr, false);
    if (gltf_.is_discarded() || !gltf_.is_object())
      fail("not a glTF file (its JSON does not parse to an object)");
    check_asset_and_extensions();

    std::vector<GaussianScene> parts;
    for (const auto& [mesh, world] : mesh_instances())
      for (const json& primitive :
           array_of(at(at(gltf_, "meshes", "glTF"), mesh, "meshes"), "primitives", "mesh")) {
        if (!primitive.contains("extensions") || !(primitive["extensions"].contains(kSplatting) ||
                                                   primitive["extensions"].contains(kSpzOnPrimitive)))
          continue;
        const std::optional<SpzStream> spz = spz_stream(primitive);
        parts.push_back(place(spz ? read_spz_primitive(primitive, *spz) : read_primitive(primitive), world));
      }
    if (parts.empty()) fail("no mesh primitive with the KHR_gaussian_splatting extension");
    if (!spz_versions_.empty()) *format += " (SPZ " + spz_versions_ + ")";
    if (parts.size() == 1) return std::move(parts.front());
    return merge_scenes(parts);
  }

 private:
  const json& at(const json& object, const char* key, const std::string& where) const {
    if (!object.is_object() || !object.contains(key)) fail(where + " has no '" + key + "'");
    return object.at(key);
  }
  const json& at(const json& array, size_t index, const std::string& what) const {
    if (!array.is_array() || index >= array.size())
      fail("index " + std::to_string(index) + " is outside " + what + " (" +
           std::to_string(array.is_array() ? array.size() : 0) + ")");
    return array[index];
  }
  const json& array_of(const json& object, const char* key, const std::string& where) const {
    const json& value = at(object, key, where);
    if (!value.is_array()) fail(where + "." + key + " is not an array");
    return value;
  }
  size_t index(const json& value, const std::string& what) const {
    if (!value.is_number_unsigned()) fail(what + " is not an index");
    return value.get<size_t>();
  }
  bool boolean(const json& value, const std::string& what) const {
    if (!value.is_boolean()) fail(what + " is not true or false");
    return value.get<bool>();
  }
  double number(const json& value, const std::string& what) const {
    if (!value.is_number()) fail(what + " is not a number");
    return value.get<double>();
  }

  void check_asset_and_extensions() const {
    const json& asset = at(gltf_, "asset", "glTF");
    const json& version = at(asset, "version", "asset");
    if (!version.is_string() || !version.get<std::string>().starts_with("2."))
      fail("unsupported glTF version " + version.dump() + " (supported: 2.x)");
    if (gltf_.contains("extensionsRequired"))
      for (const json& extension : gltf_["extensionsRequired"])
        if (extension != kSplatting && extension != kSpzOnPrimitive && extension != kSpzInSplatting[0] &&
            extension != kSpzInSplatting[1])
          fail("requires the glTF extension " + extension.dump() +
               ", which this reader does not decode (it reads KHR_gaussian_splatting with plain accessors "
               "or an SPZ stream)");
  }

  // Where a primitive's SPZ stream is, if it has one.
  struct SpzStream {
    std::string extension;
    size_t buffer_view = 0;
  };
  std::optional<SpzStream> spz_stream(const json& primitive) const {
    const json& extensions = primitive["extensions"];
    const auto view_of = [&](const json& extension, const char* name) {
      if (!extension.is_object()) fail(std::string(name) + " is not an object");
      return SpzStream{name, index(at(extension, "bufferView", name), std::string(name) + ".bufferView")};
    };
    if (extensions.contains(kSplatting) && extensions[kSplatting].is_object() &&
        extensions[kSplatting].contains("extensions"))
      for (const char* name : kSpzInSplatting)
        if (extensions[kSplatting]["extensions"].contains(name))
          return view_of(extensions[kSplatting]["extensions"][name], name);
    if (extensions.contains(kSpzOnPrimitive)) return view_of(extensions[kSpzOnPrimitive], kSpzOnPrimitive);
    return std::nullopt;
  }

  // (mesh, world matrix) for every node of the default scene (or of every root, without scenes).
  std::vector<std::pair<size_t, Matrix4>> mesh_instances() const {
    std::vector<std::pair<size_t, Matrix4>> instances;
    const json empty = json::array();
    const json& nodes = gltf_.contains("nodes") ? gltf_["nodes"] : empty;
    std::vector<size_t> roots;
    if (gltf_.contains("scenes")) {
      const size_t scene = gltf_.contains("scene") ? index(gltf_["scene"], "scene") : 0;
      const json& root = at(gltf_["scenes"], scene, "scenes");
      if (root.contains("nodes"))
        for (const json& node : root["nodes"]) roots.push_back(index(node, "scene node"));
    } else if (gltf_.contains("meshes")) {  // no scene: every mesh once, untransformed
      for (size_t m = 0; m < gltf_["meshes"].size(); ++m) instances.push_back({m, kIdentity});
      return instances;
    }
    // Depth-first; a depth bound keeps a cyclic (invalid) hierarchy from looping.
    struct Visit {
      size_t node;
      Matrix4 parent;
      size_t depth;
    };
    std::vector<Visit> stack;
    for (size_t root : roots) stack.push_back({root, kIdentity, 0});
    while (!stack.empty()) {
      const Visit visit = stack.back();
      stack.pop_back();
      if (visit.depth > 64) fail("the node hierarchy is deeper than 64 levels (or has a cycle)");
      const json& node = at(nodes, visit.node, "nodes");
      const Matrix4 world = multiply(visit.parent, local_matrix(name_, node));
      if (node.contains("mesh")) instances.push_back({index(node["mesh"], "node.mesh"), world});
      if (node.contains("children"))
        for (const json& child : node["children"])
          stack.push_back({index(child, "node child"), world, visit.depth + 1});
    }
    return instances;
  }

  std::span<const unsigned char> buffer(size_t i) {
    if (i < loaded_.size() && loaded_[i]) return *loaded_[i];
    const json& description = at(array_of(gltf_, "buffers", "glTF"), i, "buffers");
    if (loaded_.size() <= i) loaded_.resize(i + 1);
    if (!description.contains("uri")) {
      if (!bin_) fail("buffer " + std::to_string(i) + " has no uri and the file no GLB binary chunk");
      return *bin_;  // the file's own bytes, not a copy
    }
    const json& uri_value = description["uri"];
    if (!uri_value.is_string()) fail("buffer " + std::to_string(i) + ": uri is not a string");
    const std::string uri = uri_value.get<std::string>();
    if (uri.starts_with("data:")) {
      const size_t comma = uri.find(',');
      if (comma == std::string::npos || uri.substr(0, comma).find(";base64") == std::string::npos)
        fail("buffer " + std::to_string(i) + ": only base64 data: URIs are supported");
      loaded_[i] = decode_base64(name_, std::string_view(uri).substr(comma + 1));
    } else {
      if (!load_buffer_)
        fail("buffer " + std::to_string(i) + " is the external file '" + uri + "': read the .gltf from disk");
      loaded_[i] = load_buffer_(percent_decoded(name_, uri, i));
    }
    return *loaded_[i];
  }

  // The bytes of bufferView `i`, checked to lie inside its buffer; `user` names who asked, for errors.
  std::span<const unsigned char> buffer_view(size_t i, const std::string& user) {
    const json& view = at(array_of(gltf_, "bufferViews", "glTF"), i, "bufferViews");
    const std::span<const unsigned char> data =
        buffer(index(at(view, "buffer", "bufferView"), "bufferView.buffer"));
    const size_t view_offset =
        view.contains("byteOffset") ? index(view["byteOffset"], "bufferView.byteOffset") : 0;
    const size_t view_length = index(at(view, "byteLength", "bufferView"), "bufferView.byteLength");
    if (view_offset > data.size() || view_length > data.size() - view_offset)
      fail("bufferView " + std::to_string(i) + " of " + user + " lies outside its buffer (" +
           std::to_string(data.size()) + " bytes)");
    return data.subspan(view_offset, view_length);
  }

  // An accessor's values as doubles, `components` per element; normalized integers mapped by the
  // glTF rules (signed: max(v / MAX, -1)). `allowed` lists the component types this attribute may use.
  std::vector<double> accessor(size_t i, const std::string& attribute, size_t components, size_t count,
                               std::initializer_list<int> allowed) {
    const std::string where = "accessor " + std::to_string(i) + " (" + attribute + ")";
    const json& a = at(array_of(gltf_, "accessors", "glTF"), i, "accessors");
    static const std::pair<const char*, size_t> kTypes[] = {
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}};
    const json& type = at(a, "type", where);
    size_t type_components = 0;
    for (const auto& [type_name, n] : kTypes)
      if (type == type_name) type_components = n;
    if (type_components != components)
      fail(where + " has type " + type.dump() + "; expected " + std::to_string(components) + " components");
    // One of glTF's GL enums (5120 to 5126): a number past int's range is refused before it becomes one.
    const json& component_json = at(a, "componentType", where);
    const double component_number = number(component_json, where + ".componentType");
    if (!(component_number >= 0 && component_number <= 65535))
      fail(where + " has component type " + component_json.dump() +
           ", which the extension does not allow for it");
    const int component_type = static_cast<int>(component_number);
    if (std::find(allowed.begin(), allowed.end(), component_type) == allowed.end())
      fail(where + " has component type " + std::to_string(component_type) +
           ", which the extension does not allow for it");
    const size_t elements = index(at(a, "count", where), where + ".count");
    if (elements != count)
      fail(where + " has " + std::to_string(elements) + " elements; POSITION has " + std::to_string(count));
    if (a.contains("sparse")) fail(where + " is sparse, which this reader does not support");
    const bool normalized = a.contains("normalized") && boolean(a["normalized"], where + ".normalized");
    const size_t size = component_type == 5126 || component_type == 5125   ? 4
                        : component_type == 5122 || component_type == 5123 ? 2
                                                                           : 1;
    if (!a.contains("bufferView")) {
      // All zeros, per the glTF spec; POSITION's count, proven by its own buffer, sizes it.
      if (attribute == "POSITION") fail(where + " has no bufferView");
      return std::vector<double>(count * components);
    }
    const size_t view_index = index(a["bufferView"], where + ".bufferView");
    const std::span<const unsigned char> view_bytes = buffer_view(view_index, where);
    const json& view = gltf_["bufferViews"][view_index];
    const size_t view_length = view_bytes.size();
    const size_t element_size = size * components;
    const size_t stride =
        view.contains("byteStride") ? index(view["byteStride"], "bufferView.byteStride") : element_size;
    const size_t offset = a.contains("byteOffset") ? index(a["byteOffset"], where + ".byteOffset") : 0;
    if (stride < element_size)
      fail(where + ": byteStride " + std::to_string(stride) + " is smaller than an element");
    if (count > 0) {
      uint64_t span = 0;
      if (!checked_multiply(count - 1, stride, &span) || offset > view_length ||
          span > view_length - offset || element_size > view_length - offset - span)
        fail(where + ": " + std::to_string(count) + " elements run past the end of its bufferView (" +
             std::to_string(view_length) + " bytes); the file is truncated or the count is wrong");
    }
    std::vector<double> values(count * components);
    const unsigned char* base = view_bytes.data() + offset;
    for (size_t e = 0; e < count; ++e)
      for (size_t c = 0; c < components; ++c) {
        const unsigned char* p = base + e * stride + c * size;
        double v = 0;
        switch (component_type) {
          case 5126:
            v = load_le<float>(p);
            break;
          case 5120:
            v = normalized ? std::max(static_cast<int8_t>(*p) / 127.0, -1.0) : static_cast<int8_t>(*p);
            break;
          case 5121:
            v = normalized ? *p / 255.0 : *p;
            break;
          case 5122:
            v = normalized ? std::max(load_le<int16_t>(p) / 32767.0, -1.0) : load_le<int16_t>(p);
            break;
          case 5123:
            v = normalized ? load_le<uint16_t>(p) / 65535.0 : load_le<uint16_t>(p);
            break;
          default:
            fail(where + ": unsupported component type " + std::to_string(component_type));
        }
        values[e * components + c] = v;
      }
    return values;
  }

  GaussianScene read_primitive(const json& primitive) {
    const json& attributes = at(primitive, "attributes", "the primitive");
    if (primitive.contains("mode") && primitive["mode"] != 0)
      fail("a KHR_gaussian_splatting primitive must have mode POINTS (0)");
    const auto attribute = [&](const std::string& semantic) -> std::optional<size_t> {
      if (!attributes.contains(semantic)) return std::nullopt;
      return index(attributes[semantic], "attribute " + semantic);
    };
    const auto required = [&](const std::string& semantic) {
      const auto i = attribute(semantic);
      if (!i) fail("the KHR_gaussian_splatting primitive lacks the attribute " + semantic);
      return *i;
    };
    const size_t position_index = required("POSITION");
    const json& position_accessor = at(array_of(gltf_, "accessors", "glTF"), position_index, "accessors");
    const size_t count = index(at(position_accessor, "count", "POSITION accessor"), "POSITION count");
    // Every accessor of `count` elements must fit its buffer: a count is checked there before the
    // scene's arrays are sized by it.
    const std::vector<double> positions = accessor(position_index, "POSITION", 3, count, {5126});
    const std::vector<double> rotations =
        accessor(required(std::string(kPrefix) + "ROTATION"), "ROTATION", 4, count, {5126, 5120, 5122});
    const std::vector<double> scales =
        accessor(required(std::string(kPrefix) + "SCALE"), "SCALE", 3, count, {5126, 5120, 5122});
    const std::vector<double> opacities =
        accessor(required(std::string(kPrefix) + "OPACITY"), "OPACITY", 1, count, {5126, 5121, 5123});

    int degree = 0;
    while (degree < 3 &&
           attribute(std::string(kPrefix) + "SH_DEGREE_" + std::to_string(degree + 1) + "_COEF_0"))
      ++degree;
    GaussianScene scene;
    allocate_scene(scene, count, degree);
    const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
    size_t k = 0;
    for (int l = 0; l <= degree; ++l)
      for (int n = 0; n < 2 * l + 1; ++n, ++k) {
        const std::string semantic =
            std::string(kPrefix) + "SH_DEGREE_" + std::to_string(l) + "_COEF_" + std::to_string(n);
        std::vector<double> values;
        if (const auto i = attribute(semantic)) {
          values = accessor(*i, semantic, 3, count, {5126});
        } else if (l == 0 && attribute("COLOR_0")) {  // no SH: the display colour is the DC term
          values = accessor(*attribute("COLOR_0"), "COLOR_0", 4, count, {5126, 5121, 5123});
          std::vector<double> rgb;
          for (size_t e = 0; e < count; ++e)
            for (size_t c = 0; c < 3; ++c) rgb.push_back((values[4 * e + c] - 0.5) / kShC0);
          values = std::move(rgb);
        } else {
          fail("the KHR_gaussian_splatting primitive lacks " + semantic +
               (l == 0 ? "" : " (SH degrees must be complete)"));
        }
        for (size_t e = 0; e < count; ++e)
          for (size_t c = 0; c < 3; ++c)
            scene.sh[(e * coefficients + k) * 3 + c] = to_float(values[3 * e + c]);
      }
    for (size_t e = 0; e < count; ++e) {
      for (size_t a = 0; a < 3; ++a) {
        scene.positions[3 * e + a] = to_float(positions[3 * e + a]);
        scene.log_scales[3 * e + a] = to_float(std::log(scales[3 * e + a]));  // <= 0: -inf or NaN, dropped
      }
      const double* q = rotations.data() + 4 * e;  // x y z w
      scene.rotations[4 * e] = to_float(q[3]);
      for (size_t j = 0; j < 3; ++j) scene.rotations[4 * e + 1 + j] = to_float(q[j]);
      const double opacity = opacities[e];
      scene.opacity_logits[e] = opacity >= 0 && opacity <= 1 ? static_cast<float>(clamped_logit(opacity))
                                                             : std::numeric_limits<float>::quiet_NaN();
    }
    return scene;
  }

  // A primitive whose Gaussians are an SPZ stream, in glTF's axes as read_primitive gives them.
  GaussianScene read_spz_primitive(const json& primitive, const SpzStream& spz) {
    const std::span<const unsigned char> bytes = buffer_view(spz.buffer_view, spz.extension);
    const SpzPacked packed = unpack_spz(bytes, spz);
    // What the primitive says the stream holds must be what it holds: a mismatch is a damaged file.
    const auto expect_count = [&](size_t declared, const std::string& by) {
      if (declared != packed.size())
        fail(by + " says " + std::to_string(declared) + " Gaussians; the SPZ stream holds " +
             std::to_string(packed.size()));
    };
    if (primitive.contains("attributes") && primitive["attributes"].contains("POSITION")) {
      const json& accessor = at(array_of(gltf_, "accessors", "glTF"),
                                index(primitive["attributes"]["POSITION"], "attribute POSITION"), "accessors");
      expect_count(index(at(accessor, "count", "POSITION accessor"), "POSITION count"), "the POSITION accessor");
    }
    const json& extension = spz.extension == kSpzOnPrimitive ? primitive["extensions"][kSpzOnPrimitive]
                                                             : json::object();
    if (extension.contains("numPoints"))
      expect_count(index(extension["numPoints"], "numPoints"), spz.extension + ".numPoints");
    const std::string version = "v" + std::to_string(packed.version()) + " in " + spz.extension;
    if (spz_versions_.find(version) == std::string::npos)
      spz_versions_ += (spz_versions_.empty() ? "" : ", ") + version;
    if (packed.has_extensions()) spz_ignored_extensions_ = true;
    GaussianScene scene = packed.decode_all();
    turn_about_z(scene);  // SPZ's decoding lands in the engine's axes; place() expects glTF's
    return scene;
  }

  // The stream's SPZ reader, its errors told as this file's: "NAME: EXTENSION stream in bufferView N: what".
  SpzPacked unpack_spz(std::span<const unsigned char> bytes, const SpzStream& spz) const {
    try {
      return SpzPacked(std::as_bytes(bytes), name_);
    } catch (const SceneError& error) {
      std::string what = error.what();
      const std::string prefix = std::string(name_) + ": ";
      if (what.starts_with(prefix)) what.erase(0, prefix.size());
      fail(spz.extension + " stream in bufferView " + std::to_string(spz.buffer_view) + ": " + what);
    }
  }

  // glTF's axes to the engine's and back: 180 degrees about z, so x and y flip (positions, quaternions,
  // and SH coefficients by their parity in x and y).
  static void turn_about_z(GaussianScene& scene) {
    const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
    for (size_t e = 0; e < scene.size(); ++e) {
      scene.positions[3 * e] = -scene.positions[3 * e];
      scene.positions[3 * e + 1] = -scene.positions[3 * e + 1];
      // q_z(180) q = (-z, -y, x, w); the negation of that is the same rotation.
      float* q = scene.rotations.data() + 4 * e;
      const std::array<float, 4> old = {q[0], q[1], q[2], q[3]};
      q[0] = old[3];
      q[1] = old[2];
      q[2] = -old[1];
      q[3] = -old[0];
      float* sh = scene.sh.data() + 3 * coefficients * e;
      for (size_t k = 1; k < coefficients; ++k)
        for (size_t c = 0; c < 3; ++c) sh[3 * k + c] *= kFlipSh[k - 1];
    }
  }

 public:
  bool spz_ignored_extensions() const { return spz_ignored_extensions_; }

 private:
  // The node's world transform, then glTF's axes to the engine's (x and y flip).
  GaussianScene place(GaussianScene scene, const Matrix4& world) const {
    if (world != kIdentity) {
      ModelTransform transform;
      std::array<double, 3> column_norm{};
      for (int col = 0; col < 3; ++col)
        column_norm[col] =
            std::sqrt(world[col * 4] * world[col * 4] + world[col * 4 + 1] * world[col * 4 + 1] +
                      world[col * 4 + 2] * world[col * 4 + 2]);
      const double s = column_norm[0];
      if (!(s > 0) || std::fabs(column_norm[1] - s) > 1e-6 * s || std::fabs(column_norm[2] - s) > 1e-6 * s ||
          world[3] != 0 || world[7] != 0 || world[11] != 0 || world[15] != 1)
        fail(
            "a node transform with a non-uniform scale, a shear or a projection: Gaussians can only be "
            "moved, "
            "rotated and scaled uniformly");
      std::array<double, 9> r{};  // row-major rotation
      for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row) r[row * 3 + col] = world[col * 4 + row] / s;
      const double trace = r[0] + r[4] + r[8];
      std::array<double, 4> q{};
      if (trace > 0) {
        const double t = std::sqrt(trace + 1.0) * 2;
        q = {0.25 * t, (r[7] - r[5]) / t, (r[2] - r[6]) / t, (r[3] - r[1]) / t};
      } else if (r[0] > r[4] && r[0] > r[8]) {
        const double t = std::sqrt(1.0 + r[0] - r[4] - r[8]) * 2;
        q = {(r[7] - r[5]) / t, 0.25 * t, (r[1] + r[3]) / t, (r[2] + r[6]) / t};
      } else if (r[4] > r[8]) {
        const double t = std::sqrt(1.0 + r[4] - r[0] - r[8]) * 2;
        q = {(r[2] - r[6]) / t, (r[1] + r[3]) / t, 0.25 * t, (r[5] + r[7]) / t};
      } else {
        const double t = std::sqrt(1.0 + r[8] - r[0] - r[4]) * 2;
        q = {(r[3] - r[1]) / t, (r[2] + r[6]) / t, (r[5] + r[7]) / t, 0.25 * t};
      }
      transform.rotation = q;
      transform.scale = {s, s, s};
      transform.translation = {world[12], world[13], world[14]};
      try {
        scene = transform_scene(scene, transform);
      } catch (const std::invalid_argument& error) {
        fail(std::string("node transform: ") + error.what());
      }
    }
    turn_about_z(scene);
    return scene;
  }

  std::string_view name_;
  const FileLoader& load_buffer_;
  json gltf_;
  std::optional<std::span<const unsigned char>> bin_;
  std::vector<std::optional<std::vector<unsigned char>>> loaded_;
  std::string spz_versions_;  // "v3 in KHR_gaussian_splatting_compression_spz_2", ... as read
  bool spz_ignored_extensions_ = false;
};

}  // namespace

GaussianScene read_gltf(std::span<const std::byte> data, std::string_view name, const FileLoader& load_buffer,
                        const LoadOptions& options, LoadReport* report) {
  if (data.empty()) fail(name, "empty file, not a glTF file");
  GltfReader reader(name, load_buffer);
  std::string format;
  GaussianScene scene = reader.read(data, &format);
  finish_scene(scene, name, options, format, "2.0", report);
  if (report && reader.spz_ignored_extensions()) report->ignored_properties.push_back(kSpzExtensionsIgnored);
  return scene;
}

}  // namespace tilesplat::detail
