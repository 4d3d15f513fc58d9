// tilesplat._core: the engine's public API for Python, numpy arrays in and out (nanobind).
//
// Scenes, cameras, the renderer and its images are the C++ types with thin wrappers: a scene's arrays
// and an image's channels are numpy views of the C++ vectors, kept alive by the Python object that
// owns them; render() releases the GIL while the frame runs. C++ exceptions reach Python with their
// messages: SceneError as tilesplat.SceneError (a ValueError), std::invalid_argument as ValueError, a
// missing file as FileNotFoundError, anything else as RuntimeError.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/unique_ptr.h>
#include <nanobind/stl/vector.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/camera_sets.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/reference.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/scene_in_parts.h"
#include "tilesplat/shutter.h"
#include "tilesplat/version.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace tilesplat::python {
namespace {

template <typename T>
using NumpyArray = nb::ndarray<nb::numpy, T>;

// A numpy view of `values` with the given shape, kept alive by `owner` (the Python object that holds
// the vector).
template <typename T>
NumpyArray<T> view_of(std::vector<T>& values, std::initializer_list<size_t> shape, nb::handle owner) {
  return NumpyArray<T>(values.data(), shape, owner);
}

// A numpy array that owns `values` (moved to the heap, freed with the array), with the given shape.
template <typename T>
NumpyArray<T> owned_array(std::vector<T>&& values, std::initializer_list<size_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  nb::capsule owner(owned, [](void* pointer) noexcept { delete static_cast<std::vector<T>*>(pointer); });
  return NumpyArray<T>(owned->data(), shape, owner);
}

// A C-contiguous float32 array on the CPU; other dtypes and layouts are converted (copied) on the way in.
using FloatInput = nb::ndarray<const float, nb::c_contig, nb::device::cpu>;

// The values of `array`, which must have the shape given (-1: any size on that axis), all finite.
std::vector<float> finite_values(const FloatInput& array, const char* name,
                                 std::initializer_list<int64_t> shape) {
  std::string expected = "(";
  for (auto it = shape.begin(); it != shape.end(); ++it)
    expected += (it == shape.begin() ? "" : ", ") + (*it < 0 ? std::string("N") : std::to_string(*it));
  expected += shape.size() == 1 ? ",)" : ")";
  bool matches = array.ndim() == shape.size();
  size_t axis = 0;
  for (const int64_t size : shape) {
    if (matches && size >= 0 && array.shape(axis) != size_t(size)) matches = false;
    ++axis;
  }
  if (!matches) {
    std::string got = "(";
    for (size_t a = 0; a < array.ndim(); ++a) got += (a ? ", " : "") + std::to_string(array.shape(a));
    got += array.ndim() == 1 ? ",)" : ")";
    throw std::invalid_argument(std::string(name) + " must have the shape " + expected + ", got " + got);
  }
  std::vector<float> values(array.data(), array.data() + array.size());
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw std::invalid_argument(std::string(name) + " holds a non-finite value (" +
                                  std::to_string(values[i]) + ") at flat index " + std::to_string(i));
  return values;
}

template <typename Enum, size_t N>
Enum parse_choice(const std::string& name, const std::string& text, const std::array<Enum, N>& choices) {
  std::string allowed;
  for (const Enum choice : choices) {
    if (to_string(choice) == text) return choice;
    allowed += (allowed.empty() ? "" : ", ") + to_string(choice);
  }
  throw std::invalid_argument(name + " must be one of " + allowed + ", got '" + text + "'");
}

// Raises FileNotFoundError naming the file, as open() would, before the engine reads it.
void check_exists(const std::filesystem::path& path, const char* what) {
  std::error_code error;
  if (std::filesystem::exists(path, error)) return;
  const std::string message = std::string("cannot read ") + what + " '" + path.string() + "': no such file";
  PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
  throw nb::python_error();
}

// RenderSettings from render()'s keyword arguments (the C++ names).
RenderSettings make_settings(const std::string& sort, bool depth, bool splat_count,
                             const std::string& accuracy, const std::string& antialiasing,
                             const std::string& compositor, uint32_t stochastic_frames, uint32_t seed,
                             const std::array<float, 3>& background, bool reuse_lists, double near_plane,
                             double max_alpha, const std::optional<ThinLens>& lens,
                             const std::optional<Shutter>& shutter, uint64_t memory_budget) {
  RenderSettings settings;
  settings.sort = sort;
  settings.depth = depth;
  settings.splat_count = splat_count;
  settings.accuracy = parse_accuracy_modes(accuracy);
  settings.antialiasing =
      parse_choice("antialiasing", antialiasing,
                   std::array{Antialiasing::kClassic, Antialiasing::kAntialiased, Antialiasing::kMip});
  settings.compositor =
      parse_choice("compositor", compositor,
                   std::array{Compositor::kSorted, Compositor::kStochastic, Compositor::kRaster});
  settings.stochastic.frames = stochastic_frames;
  settings.stochastic.seed = seed;
  settings.background = background;
  settings.reuse_lists = reuse_lists;
  settings.near_plane = near_plane;
  settings.max_alpha = max_alpha;
  if (lens) settings.lens = *lens;
  if (shutter) settings.shutter = *shutter;
  settings.memory_budget = memory_budget;
  return settings;
}

// SaturatedValues as {channel: count}.
nb::dict saturated_dict(const SaturatedValues& saturated) {
  nb::dict out;
  for (const auto& [channel, count] : saturated.channels) out[channel.c_str()] = count;
  return out;
}

nb::dict stats_dict(const FrameStats& stats) {
  nb::dict out;
  nb::list passes;
  for (const PassTiming& pass : stats.passes) passes.append(nb::make_tuple(pass.name, pass.gpu_ms));
  out["passes"] = passes;
  out["gpu_ms"] = stats.gpu_ms;
  out["cpu_ms"] = stats.cpu_ms;
  out["gaussians"] = stats.gaussians;
  out["visible"] = stats.visible;
  out["intersections"] = stats.intersections;
  out["sort_bits"] = stats.sort_bits;
  out["sort_strategy"] = stats.sort_strategy;
  out["retries"] = stats.retries;
  out["submissions"] = stats.submissions;
  out["device_bytes"] = stats.device_bytes;
  out["reused_sorted_lists"] = stats.reused_sorted_lists;
  out["samples"] = stats.samples;  // frames averaged (lens, shutter)
  out["accumulated_frames"] = stats.accumulated_frames;  // the stochastic frames in the mean
  out["accumulated_samples"] = stats.accumulated_samples;  // lens and shutter samples (accumulate_samples)
  out["scene_parts"] = stats.scene_parts;  // depth-ordered parts under a memory budget
  out["image_bands"] = stats.image_bands;  // bands of rows of an image past the device
  out["peak_device_bytes"] = stats.peak_device_bytes;
  out["depth_order_ms"] = stats.depth_order_ms;
  out["saturated"] = saturated_dict(stats.saturated);  // channel -> values saturated (FrameStats::saturated)
  return out;
}

// The Python Renderer: the engine's renderer, which is neither copyable nor movable, behind a pointer.
struct RendererHandle {
  std::unique_ptr<Renderer> renderer;
};

nb::dict device_dict(const DeviceInfo& device) {
  nb::dict out;
  out["name"] = device.name;
  out["driver"] = device.driver;
  out["subgroup_size"] = device.subgroup_size;
  out["cpu"] = device.cpu;
  out["vendor_id"] = device.vendor_id;
  out["max_image_dimension"] = device.max_image_dimension;
  out["max_allocation_size"] = device.max_allocation_size;
  out["device_memory"] = device.device_memory;
  return out;
}

}  // namespace

void bind(nb::module_& m) {
  m.attr("__version__") = build_info().version;
  nb::exception<SceneError>(m, "SceneError", PyExc_ValueError);

  // --- scenes
  nb::class_<GaussianScene>(
      m, "Scene",
      "N Gaussians as the trainer stores them (log scales, opacity logits, SH), structure "
      "of arrays; the arrays are numpy views of the scene's own memory.")
      .def_prop_ro("size", &GaussianScene::size, "N, the number of Gaussians")
      .def_prop_ro(
          "sh_degree", [](const GaussianScene& s) { return s.sh_degree; }, "0..3")
      .def_prop_ro(
          "positions",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.positions, {s.size(), 3}, self);
          },
          "(N, 3) world-space means")
      .def_prop_ro(
          "log_scales",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.log_scales, {s.size(), 3}, self);
          },
          "(N, 3) log of the scales")
      .def_prop_ro(
          "rotations",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.rotations, {s.size(), 4}, self);
          },
          "(N, 4) unit quaternions w x y z")
      .def_prop_ro(
          "opacity_logits",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.opacity_logits, {s.size()}, self);
          },
          "(N,) logits of the opacities")
      .def_prop_ro(
          "sh",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.sh, {s.size(), size_t(s.sh_coefficients()), 3}, self);
          },
          "(N, K, 3) SH coefficients, K = (sh_degree + 1)^2; k = 0 is the DC term")
      .def_static(
          "from_arrays",
          [](const FloatInput& positions, const FloatInput& log_scales, const FloatInput& rotations,
             const FloatInput& opacity_logits, const FloatInput& sh) {
            GaussianScene scene;
            scene.positions = finite_values(positions, "positions", {-1, 3});
            const size_t n = scene.positions.size() / 3;
            scene.log_scales = finite_values(log_scales, "log_scales", {int64_t(n), 3});
            scene.rotations = finite_values(rotations, "rotations", {int64_t(n), 4});
            scene.opacity_logits = finite_values(opacity_logits, "opacity_logits", {int64_t(n)});
            scene.sh = finite_values(sh, "sh", {int64_t(n), -1, 3});
            const size_t k = sh.ndim() == 3 ? sh.shape(1) : 0;
            int degree = 0;
            while (degree <= 3 && size_t((degree + 1) * (degree + 1)) != k) ++degree;
            if (degree > 3)
              throw std::invalid_argument("sh must have 1, 4, 9 or 16 coefficients, got " +
                                          std::to_string(k));
            scene.sh_degree = degree;
            return scene;
          },
          "positions"_a, "log_scales"_a, "rotations"_a, "opacity_logits"_a, "sh"_a,
          "A scene from arrays: positions (N, 3), log_scales (N, 3), rotations (N, 4) w x y z, "
          "opacity_logits "
          "(N,), sh (N, K, 3) with K = 1, 4, 9 or 16. Values are copied as given (a quaternion of any "
          "length: the "
          "renderer normalizes it, and a zero one is the identity); non-finite ones raise ValueError.")
      .def("__repr__", [](const GaussianScene& s) {
        return "<tilesplat.Scene " + std::to_string(s.size()) + " Gaussians, SH degree " +
               std::to_string(s.sh_degree) + ">";
      });

  m.def(
      "load_scene",
      [](const std::filesystem::path& path, bool strict) {
        check_exists(path, "scene");
        LoadOptions options;
        options.strict = strict;
        nb::gil_scoped_release release;
        if (is_scene_description(path)) return load_described_scene(load_scene_description(path), options);
        return load_scene(path, options);
      },
      "path"_a, "strict"_a = false,
      "Loads a scene: a splat file of any format the library reads (.ply, .compressed.ply, .splat, .spz, "
      ".sog, "
      "SOG meta.json, .glb, .gltf) or a scene file (.json). strict: fail on a non-finite value instead of "
      "dropping the Gaussian.");

  // --- a scene file's models as placed copies, some of which may move
  nb::class_<SceneInstances>(
      m, "SceneInstances",
      "A scene file's models as placed copies of their files (each file held once), where some may move "
      "(a model's \"motion\"): Renderer.render(camera, instances=..., shutter=...) blurs them while the "
      "shutter is open (docs/effects.md, \"Moving models\").")
      .def(
          "__init__",
          [](SceneInstances* self, const std::filesystem::path& path, bool strict) {
            check_exists(path, "scene file");
            LoadOptions options;
            options.strict = strict;
            nb::gil_scoped_release release;
            new (self) SceneInstances(load_scene_instances(load_scene_description(path), options));
          },
          "path"_a, "strict"_a = false, "Reads a scene file (.json) and the splat files it names.")
      .def_prop_ro("size", &SceneInstances::size, "the Gaussians of the merged scene")
      .def_prop_ro("moves", &SceneInstances::moves, "whether any model moves")
      .def(
          "scene_at",
          [](const SceneInstances& scene, double t) {
            nb::gil_scoped_release release;
            return merge_instances(scene, t);
          },
          "t"_a = 0.0, "The merged scene with every model where it is at time t in [0, 1].");

  // --- a binary PLY, an SPZ or a SOG read part by part
  nb::class_<SceneInParts>(
      m, "SceneInParts",
      "A binary PLY, an SPZ or a SOG opened to be read part by part: the Gaussians' positions are held (and "
      "an SPZ's packed bytes or a SOG's texels), and Renderer.render(camera, in_parts=..., "
      "memory_budget=...) decodes each "
      "part as it is drawn, the frame of load_scene's scene to the bit (docs/big-scenes.md, \"Read part by "
      "part\"). MappedPly is its earlier name.")
      .def(
          "__init__",
          [](SceneInParts* self, const std::filesystem::path& path, bool strict) {
            check_exists(path, "scene");
            LoadOptions options;
            options.strict = strict;
            nb::gil_scoped_release release;
            new (self) SceneInParts(SceneInParts::open(path, options));
          },
          "path"_a, "strict"_a = false,
          "Opens a binary PLY, an SPZ or a SOG (an ASCII or a compressed PLY and the other formats are "
          "refused: "
          "load_scene reads those whole).")
      .def_prop_ro("size", &SceneInParts::size, "the Gaussians")
      .def_prop_ro("sh_degree", &SceneInParts::sh_degree, "0 to 3")
      .def_static("whole_scene_bytes", &SceneInParts::whole_scene_bytes, "path"_a,
                  "The bytes load_scene's arrays would take for the file, from its header alone (0 for a "
                  "file SceneInParts does not open).")
      .def(
          "load",
          [](const SceneInParts& scene) {
            nb::gil_scoped_release release;
            return scene.load();
          },
          "The whole scene, as load_scene reads it.")
      .def("__repr__", [](const SceneInParts& scene) {
        return "<tilesplat.SceneInParts " + std::to_string(scene.size()) + " Gaussians (SH" +
               std::to_string(scene.sh_degree()) + ")>";
      });
  m.attr("MappedPly") = m.attr("SceneInParts");

  // --- level-of-detail sets
  nb::class_<LodSelection>(m, "LodSelection", "The level each chunk of a LOD set is drawn at for one camera.")
      .def_ro("chunk_levels", &LodSelection::chunk_levels, "per chunk: the level drawn, or -1 out of view")
      .def_ro("splats", &LodSelection::splats, "Gaussians drawn")
      .def_ro("coarsest_splats", &LodSelection::coarsest_splats,
              "what the chunks in view cost at their coarsest")
      .def_ro("over_budget", &LodSelection::over_budget, "the budget was below coarsest_splats")
      .def("__repr__", [](const LodSelection& s) {
        return "<tilesplat.LodSelection " + std::to_string(s.splats) + " splats of " +
               std::to_string(s.chunk_levels.size()) + " chunks>";
      });
  nb::class_<LodSet>(
      m, "LodSet",
      "A level-of-detail set: splat-transform's lod-meta.json, a scene in spatial chunks held at "
      "several levels (0 the finest). docs/big-scenes.md.")
      .def(
          "__init__",
          [](LodSet* self, const std::filesystem::path& path) {
            check_exists(path, "LOD set index");
            new (self) LodSet(LodSet::open(path));
          },
          "path"_a, "Reads and checks the index (the chunk files are read when a level needs them).")
      .def_prop_ro("levels", &LodSet::levels, "the number of levels")
      .def_prop_ro(
          "chunks", [](const LodSet& set) { return set.chunks().size(); }, "the number of chunks")
      .def("level_size", &LodSet::level_size, "level"_a, "Gaussians at a level")
      .def(
          "chunk_sizes",
          [](const LodSet& set, int level) {
            set.level_size(level);  // raises for a level the set does not have
            std::vector<uint64_t> sizes;
            for (const LodChunk& chunk : set.chunks()) sizes.push_back(chunk.levels[size_t(level)].count);
            return sizes;
          },
          "level"_a,
          "Gaussians of each chunk at a level, in the order load_level and load_selection put them")
      .def(
          "load_level",
          [](const LodSet& set, int level) {
            nb::gil_scoped_release release;
            return set.load_level(level);
          },
          "level"_a, "The scene that level draws: every chunk at it, then the environment.")
      .def(
          "select",
          [](const LodSet& set, const Camera& camera, uint64_t splat_budget) {
            return select_lod_levels(set, camera, splat_budget);
          },
          "camera"_a, "splat_budget"_a,
          "The levels the camera calls for under the budget: chunks out of view left out, the rest refined "
          "from their coarsest level where their Gaussians cover the most pixels each.")
      .def(
          "load_selection",
          [](const LodSet& set, const LodSelection& selection) {
            nb::gil_scoped_release release;
            return set.load_selection(selection);
          },
          "selection"_a, "The chunks at the levels a selection chose, then the environment.")
      .def("__repr__", [](const LodSet& set) {
        std::string counts;
        for (int level = 0; level < set.levels(); ++level)
          counts += (level ? " / " : "") + std::to_string(set.level_size(level));
        return "<tilesplat.LodSet " + std::to_string(set.levels()) + " levels (" + counts + " Gaussians)>";
      });

  // --- cameras
  nb::class_<Camera>(
      m, "Camera",
      "A pinhole camera: image size, intrinsics in pixels, world-to-camera rotation (row-major) "
      "and centre; x right, y down, z forward, as the 3DGS trainer's cameras.")
      .def(nb::init<>())
      .def_rw("width", &Camera::width)
      .def_rw("height", &Camera::height)
      .def_rw("fx", &Camera::fx)
      .def_rw("fy", &Camera::fy)
      .def_rw("cx", &Camera::cx)
      .def_rw("cy", &Camera::cy)
      .def_rw("rotation", &Camera::rotation, "world to camera, row-major 3x3 as 9 numbers")
      .def_rw("position", &Camera::position, "the camera centre in world space")
      .def_prop_rw(
          "model", [](const Camera& c) { return std::string(camera_model_name(c.model)); },
          [](Camera& c, const std::string& name) { c.model = parse_camera_model(name); },
          "'pinhole', 'opencv', 'fisheye', 'orthographic' or 'equirectangular' (docs/cameras.md)")
      .def_rw("distortion", &Camera::distortion,
              "the model's 8 coefficients: opencv k1 k2 p1 p2 k3 k4 k5 k6, fisheye k1 k2 k3 k4 0 0 0 0")
      .def(
          "fisheye", [](const Camera& c, double fov_deg) { return fisheye_camera(c, fov_deg); }, "fov_deg"_a,
          "The equidistant fisheye with this pose and size, fov_deg (up to 360) across the shorter side.")
      .def(
          "orthographic",
          [](const Camera& c, double view_height) { return orthographic_camera(c, view_height); },
          "view_height"_a, "The orthographic camera with this pose and size, view_height world units tall.")
      .def(
          "equirectangular", [](const Camera& c) { return equirectangular_camera(c); },
          "The 360x180 panorama with this pose and size (give it a 2:1 size).")
      .def(
          "resized", [](const Camera& c, int width, int height) { return resize_camera(c, width, height); },
          "width"_a, "height"_a, "The same view at another size (the field of view kept).")
      .def_static(
          "look_at",
          [](const std::array<double, 3>& eye, const std::array<double, 3>& target,
             const std::array<double, 3>& up, int width, int height, double vertical_fov_deg) {
            return look_at_camera(eye, target, up, width, height, vertical_fov_deg);
          },
          "eye"_a, "target"_a, "up"_a, "width"_a, "height"_a, "vertical_fov_deg"_a = 50.0)
      .def_static(
          "orbit",
          [](const GaussianScene& scene, int width, int height, double azimuth_deg, double elevation_deg,
             double vertical_fov_deg, double distance_scale) {
            OrbitParams orbit;
            orbit.azimuth_deg = azimuth_deg;
            orbit.elevation_deg = elevation_deg;
            orbit.vertical_fov_deg = vertical_fov_deg;
            orbit.distance_scale = distance_scale;
            return orbit_camera(scene, width, height, orbit);
          },
          "scene"_a, "width"_a = 1920, "height"_a = 1080, "azimuth_deg"_a = 0.0, "elevation_deg"_a = 20.0,
          "vertical_fov_deg"_a = 50.0, "distance_scale"_a = 1.0,
          "The camera that orbits the scene and frames it.")
      .def_static(
          "from_matrices",
          [](const std::array<double, 16>& view, const std::array<double, 16>& projection, int width,
             int height, const std::string& clip) {
            if (clip != "vulkan" && clip != "opengl")
              throw std::invalid_argument("clip must be vulkan or opengl, got '" + clip + "'");
            return Camera::from_matrices(view, projection, width, height,
                                         clip == "vulkan" ? ClipSpace::vulkan() : ClipSpace::opengl());
          },
          "view"_a, "projection"_a, "width"_a, "height"_a, "clip"_a = "vulkan",
          "The camera of a host's view and projection matrices, 16 numbers each, column-major (glm's "
          "layout); "
          "clip: the projection's convention, 'vulkan' (y down, depth 0..1) or 'opengl'.")
      .def("__eq__", [](const Camera& a, const Camera& b) { return a == b; })
      .def("__repr__", [](const Camera& c) {
        return "<tilesplat.Camera " + std::to_string(c.width) + "x" + std::to_string(c.height) +
               " fx=" + std::to_string(c.fx) + " fy=" + std::to_string(c.fy) + ">";
      });

  nb::class_<CameraView>(m, "CameraView", "A view of a camera set: its id, its image name and its camera.")
      .def_ro("id", &CameraView::id)
      .def_ro("name", &CameraView::name)
      .def_ro("camera", &CameraView::camera);

  m.def(
      "load_cameras",
      [](const std::filesystem::path& path) {
        check_exists(path, "cameras");
        return load_camera_set(path);
      },
      "path"_a,
      "The views of a camera set: the trainer's cameras.json, a transforms.json, or a COLMAP model (its "
      "folder, "
      "or its cameras/images .bin or .txt).");

  m.def(
      "orbit_cameras",
      [](const GaussianScene& scene, int frames, int width, int height, double azimuth_deg,
         double elevation_deg, double vertical_fov_deg, double distance_scale) {
        OrbitParams orbit;
        orbit.azimuth_deg = azimuth_deg;
        orbit.elevation_deg = elevation_deg;
        orbit.vertical_fov_deg = vertical_fov_deg;
        orbit.distance_scale = distance_scale;
        return orbit_cameras(scene, frames, width, height, orbit);
      },
      "scene"_a, "frames"_a, "width"_a = 1920, "height"_a = 1080, "azimuth_deg"_a = 0.0,
      "elevation_deg"_a = 20.0, "vertical_fov_deg"_a = 50.0, "distance_scale"_a = 1.0,
      "`frames` orbit cameras evenly spaced in azimuth around the scene, as tilesplat-render --orbit N.");
  m.def(
      "camera_path",
      [](const std::filesystem::path& path, int frames, int width, int height) {
        check_exists(path, "camera path");
        return sample_camera_path(load_camera_path(path), frames, width, height);
      },
      "path"_a, "frames"_a, "width"_a = 1920, "height"_a = 1080,
      "`frames` cameras along a keyframe file (docs/camera-paths.md), as tilesplat-render --path.");

  // --- the thin lens (depth of field)
  nb::class_<ThinLens>(m, "ThinLens",
                       "A thin lens for depth of field: aperture_diameter (world units; 0 = a pinhole), "
                       "focus_distance (the view depth in focus) and samples (pinhole frames averaged).")
      .def(
          "__init__",
          [](ThinLens* lens, double aperture_diameter, double focus_distance, int samples,
             const std::string& pattern) {
            new (lens) ThinLens{aperture_diameter, focus_distance, samples, parse_sample_pattern(pattern)};
            validate(*lens);
          },
          "aperture_diameter"_a = 0.0, "focus_distance"_a = 1.0, "samples"_a = 32, "pattern"_a = "even")
      .def_rw("aperture_diameter", &ThinLens::aperture_diameter)
      .def_rw("focus_distance", &ThinLens::focus_distance)
      .def_rw("samples", &ThinLens::samples)
      .def_prop_rw(
          "pattern", [](const ThinLens& lens) { return std::string(sample_pattern_name(lens.pattern)); },
          [](ThinLens& lens, const std::string& name) { lens.pattern = parse_sample_pattern(name); },
          "'even' (the golden-angle spiral of `samples`) or 'sobol' (progressive: what accumulate_samples "
          "continues)")
      .def("__repr__", [](const ThinLens& lens) {
        return "ThinLens(aperture_diameter=" + std::to_string(lens.aperture_diameter) +
               ", focus_distance=" + std::to_string(lens.focus_distance) +
               ", samples=" + std::to_string(lens.samples) + ", pattern='" +
               sample_pattern_name(lens.pattern) + "')";
      });
  m.def(
      "lens_sample",
      [](const std::string& pattern, int index, int count) {
        return lens_sample(parse_sample_pattern(pattern), index, count);
      },
      "pattern"_a, "index"_a, "count"_a,
      "Lens position `index` of a frame of `count` samples on the unit disk: pattern 'even' (the spiral "
      "of `count`) or 'sobol' (whatever the count).");
  m.def(
      "shutter_time",
      [](double open, double close, const std::string& pattern, int index, int count) {
        return shutter_time(open, close, parse_sample_pattern(pattern), index, count);
      },
      "open"_a, "close"_a, "pattern"_a, "index"_a, "count"_a,
      "Time `index` of a frame of `count` samples of a shutter open from `open` to `close`: pattern "
      "'even' (the middles of equal slices) or 'sobol' (whatever the count).");
  m.def("effect_sample_point", &effect_sample_point, "index"_a,
        "Point `index` of the progressive sample pattern in [0, 1)^3 (Sobol's sequence shifted by 1/2): "
        "dimensions 0 and 1 place the lens position, 2 the shutter's time.");
  m.def("lens_samples", &lens_samples, "count"_a,
        "The lens positions of `count` samples on the unit disk (Vogel's golden-angle spiral), as (x, y) "
        "pairs.");
  m.def("lens_sample_camera", &lens_sample_camera, "camera"_a, "lens"_a, "sample"_a,
        "The pinhole camera of one lens position: moved on the aperture, its principal point shifted so that "
        "the focus plane stays put.");
  m.def("aperture_for_f_stop", &aperture_for_f_stop, "camera"_a, "f_stop"_a, "sensor_width_mm"_a = 36.0,
        "world_units_per_metre"_a = 1.0,
        "The aperture diameter of an f-number: the focal length over f_stop.");

  // --- the shutter (motion blur)
  nb::class_<Shutter>(m, "Shutter",
                      "A shutter open from `open` to `close` (times in [0, 1]) while the camera moves to "
                      "end_camera (at time 1); samples frames averaged.")
      .def(
          "__init__",
          [](Shutter* shutter, double open, double close, int samples, std::optional<Camera> end_camera,
             const std::string& scan, const std::string& pattern) {
            new (shutter) Shutter{open,
                                  close,
                                  samples,
                                  std::move(end_camera),
                                  parse_shutter_scan(scan),
                                  parse_sample_pattern(pattern)};
            validate(*shutter);
          },
          "open"_a = 0.0, "close"_a = 0.0, "samples"_a = 16, "end_camera"_a = nb::none(), "scan"_a = "global",
          "pattern"_a = "even")
      .def_rw("open", &Shutter::open)
      .def_rw("close", &Shutter::close)
      .def_rw("samples", &Shutter::samples)
      .def_rw("end_camera", &Shutter::end_camera)
      .def_prop_rw(
          "scan", [](const Shutter& s) { return std::string(shutter_scan_name(s.scan)); },
          [](Shutter& s, const std::string& name) { s.scan = parse_shutter_scan(name); },
          "'global' (the mean over the open interval) or a rolling shutter's 'top-to-bottom', "
          "'bottom-to-top', 'left-to-right', 'right-to-left' (samples bands, each at its time)")
      .def_prop_rw(
          "pattern", [](const Shutter& s) { return std::string(sample_pattern_name(s.pattern)); },
          [](Shutter& s, const std::string& name) { s.pattern = parse_sample_pattern(name); },
          "'even' (the middles of `samples` equal slices) or 'sobol' (progressive: what accumulate_samples "
          "continues; a global shutter's)");
  m.def("shutter_times", &shutter_times, "open"_a, "close"_a, "count"_a,
        "The times of `count` samples of a shutter: the middles of equal slices of [open, close].");
  m.def("camera_between", &camera_between, "start"_a, "end"_a, "t"_a,
        "The camera at time t between start (0) and end (1): position and intrinsics blended, rotation "
        "slerped.");

  // --- images
  nb::class_<RenderImage>(
      m, "Image",
      "A rendered frame: rgba (H, W, 4) premultiplied over the background, in the trained "
      "display values (sRGB-encoded, as the photographs were: docs/colour.md), depth (H, W) "
      "expected view depth, splat_count (H, W) blended splats; numpy views of the image.")
      .def_ro("width", &RenderImage::width)
      .def_ro("height", &RenderImage::height)
      .def_prop_ro("rgba",
                   [](nb::handle self) {
                     auto& image = nb::cast<RenderImage&>(self);
                     return view_of(image.rgba, {size_t(image.height), size_t(image.width), 4}, self);
                   })
      .def_prop_ro("depth",
                   [](nb::handle self) -> std::optional<NumpyArray<float>> {
                     auto& image = nb::cast<RenderImage&>(self);
                     if (image.depth.empty()) return std::nullopt;
                     return view_of(image.depth, {size_t(image.height), size_t(image.width)}, self);
                   })
      .def_prop_ro("splat_count",
                   [](nb::handle self) -> std::optional<NumpyArray<uint32_t>> {
                     auto& image = nb::cast<RenderImage&>(self);
                     if (image.splat_count.empty()) return std::nullopt;
                     return view_of(image.splat_count, {size_t(image.height), size_t(image.width)}, self);
                   })
      .def(
          "write_exr",
          [](const RenderImage& image, const std::filesystem::path& path, bool half,
             const std::string& compression, std::optional<Camera> camera, float empty_depth) {
            ExrWriteOptions options;
            options.half = half;
            options.empty_depth = empty_depth;
            options.compression = parse_choice("compression", compression,
                                               std::array{ExrCompression::kZip, ExrCompression::kPiz,
                                                          ExrCompression::kDwaa, ExrCompression::kNone});
            options.camera = camera;
            return saturated_dict(write_exr(path, image, options));
          },
          "path"_a, "half"_a = false, "compression"_a = "zip", "camera"_a = nb::none(),
          "empty_depth"_a = kFarDepth,
          "Writes the image as tilesplat-render does: R G B A, Z and 'splats', scene-linear, atomically; Z "
          "is "
          "empty_depth where no splat was blended (default: far, behind everything, as the app writes). "
          "A finite value past the range of its channel's type (float, or half with half=True) is stored as "
          "that type's largest finite value, never as inf; returns {channel: values saturated so}, empty "
          "when none were.")
      .def(
          "write_png",
          [](const RenderImage& image, const std::filesystem::path& path, double exposure_stops,
             const std::string& tone_map) {
            PreviewOptions options;
            options.exposure_stops = exposure_stops;
            options.tone_map = parse_choice("tone_map", tone_map,
                                            std::array{ToneMap::kNone, ToneMap::kAces, ToneMap::kReinhard});
            write_png_preview(path, image, options);
          },
          "path"_a, "exposure_stops"_a = 0.0, "tone_map"_a = "none", "Writes an 8-bit sRGB preview.")
      .def(
          "preview",
          [](const RenderImage& image, double exposure_stops, const std::string& tone_map) {
            PreviewOptions options;
            options.exposure_stops = exposure_stops;
            options.tone_map = parse_choice("tone_map", tone_map,
                                            std::array{ToneMap::kNone, ToneMap::kAces, ToneMap::kReinhard});
            return owned_array(preview_pixels(image, options),
                               {size_t(image.height), size_t(image.width), 3});
          },
          "exposure_stops"_a = 0.0, "tone_map"_a = "none",
          "The PNG preview's pixels, (H, W, 3) uint8 sRGB, for showing the frame (matplotlib's imshow): "
          "rgba holds display values already, so they are shown as they are unless graded.");

  m.def(
      "read_exr",
      [](const std::filesystem::path& path) {
        check_exists(path, "EXR");
        return read_exr(path);
      },
      "path"_a, "Reads an EXR that write_exr (or tilesplat-render) wrote.");

  m.def(
      "compare_images",
      [](const RenderImage& a, const RenderImage& b) {
        const ImageDifference difference = compare_images(a, b);
        nb::dict out;
        out["psnr_db"] = difference.psnr_db;
        out["max_abs"] = difference.max_abs;
        out["max_abs_alpha"] = difference.max_abs_alpha;
        return out;
      },
      "a"_a, "b"_a, "PSNR (RGB, peak 1) and the largest differences of two images of one size.");

  m.def(
      "render_reference",
      [](const Camera& camera, const GaussianScene* scene, const SceneInstances* instances, bool depth,
         bool splat_count, const std::string& accuracy, const std::string& antialiasing,
         const std::string& compositor, const std::array<float, 3>& background, double near_plane,
         double max_alpha, const std::optional<ThinLens>& lens, const std::optional<Shutter>& shutter,
         const std::optional<std::array<int, 4>>& region) {
        if (int(scene != nullptr) + int(instances != nullptr) != 1)
          throw std::invalid_argument("render_reference takes one of scene and instances");
        RenderSettings settings =
            make_settings("auto", depth, splat_count, accuracy, antialiasing, compositor, 1, 1, background,
                          true, near_plane, max_alpha, lens, shutter, 0);
        if (region) settings.region = {(*region)[0], (*region)[1], (*region)[2], (*region)[3]};
        nb::gil_scoped_release release;
        return instances ? render_reference(*instances, camera, settings)
                         : render_reference(*scene, camera, settings);
      },
      "camera"_a, "scene"_a = nb::none(), "instances"_a = nb::none(), "depth"_a = true,
      "splat_count"_a = true, "accuracy"_a = "reference", "antialiasing"_a = "classic",
      "compositor"_a = "sorted", "background"_a = std::array<float, 3>{0, 0, 0},
      "near_plane"_a = kDefaultNearPlane, "max_alpha"_a = kDefaultMaxAlpha, "lens"_a = nb::none(),
      "shutter"_a = nb::none(), "region"_a = nb::none(),
      "The float64 CPU reference the GPU renderer is held to (docs/rendering-math.md): the frame of `scene` "
      "(or SceneInstances `instances`) from `camera`, in double precision on the host's cores, with "
      "Renderer.render's keywords that apply to it (compositor 'sorted' or 'raster', whose rule it has; "
      "accuracy modes such as 'resort16' change its per-pixel order). Slow: seconds for a small image of "
      "a real scene. Releases the GIL.");

  // --- the renderer
  m.def("devices", &list_devices, "The Vulkan devices, in the order Renderer(device=INDEX) counts them.");
  m.def("sort_strategies", &sort_strategies,
        "The sort strategies Renderer.render(sort=...) accepts, besides auto.");

  nb::class_<RendererHandle>(
      m, "Renderer", "The GPU renderer on one Vulkan device. render() releases the GIL while the frame runs.")
      .def(
          "__init__",
          [](RendererHandle* self, const std::string& device, bool validation) {
            RendererOptions options;
            options.device = device;
            options.validation = validation;
            std::unique_ptr<Renderer> renderer;
            {
              nb::gil_scoped_release release;
              renderer = Renderer::create(options);
            }
            new (self) RendererHandle{std::move(renderer)};
          },
          "device"_a = "", "validation"_a = false,
          "device: an index into devices(), part of a device's name or its UUID; '' = $TILESPLAT_DEVICE, "
          "else the "
          "first discrete GPU, else the first device. validation: the Khronos validation layer.")
      .def(
          "set_scene",
          [](RendererHandle& self, const GaussianScene& scene) {
            nb::gil_scoped_release release;
            self.renderer->set_scene(scene);
          },
          "scene"_a, "Uploads the scene (a copy: the Python scene stays free to change).")
      .def(
          "set_scene",
          [](RendererHandle& self, const SceneInstances& instances) {
            nb::gil_scoped_release release;
            self.renderer->set_scene(instances);
          },
          "instances"_a,
          "Uploads a scene file's placed copies where they are at time 0 and, when some move, keeps them (a "
          "copy): render(camera, shutter=...) then places them at each time sample, one a call with "
          "accumulate_samples=True; a closed shutter sees them at time 0.")
      .def(
          "render",
          [](RendererHandle& self, const Camera& camera, const std::string& sort, bool depth,
             bool splat_count, const std::string& accuracy, const std::string& antialiasing,
             const std::string& compositor, uint32_t stochastic_frames, uint32_t seed,
             const std::array<float, 3>& background, bool reuse_lists, double near_plane, double max_alpha,
             const std::optional<ThinLens>& lens, const std::optional<Shutter>& shutter,
             const GaussianScene* scene, uint64_t memory_budget, const LodSet* lod_set, uint64_t splat_budget,
             const SceneInstances* instances, const std::optional<std::array<int, 4>>& region,
             const std::string& stochastic_sampler, bool stochastic_accumulate, bool accumulate_samples,
             const SceneInParts* mapped_ply, const SceneInParts* in_parts) {
            RenderSettings settings = make_settings(
                sort, depth, splat_count, accuracy, antialiasing, compositor, stochastic_frames, seed,
                background, reuse_lists, near_plane, max_alpha, lens, shutter, memory_budget);
            settings.stochastic.sampler =
                parse_choice("stochastic_sampler", stochastic_sampler,
                             std::array{StochasticSampler::kHash, StochasticSampler::kStratified,
                                        StochasticSampler::kSobol});
            settings.stochastic.accumulate = stochastic_accumulate;
            settings.accumulate_samples = accumulate_samples;
            if (region) settings.region = {(*region)[0], (*region)[1], (*region)[2], (*region)[3]};
            if (mapped_ply && in_parts)
              throw std::invalid_argument("render takes in_parts or mapped_ply (its earlier name), not both");
            if (mapped_ply) in_parts = mapped_ply;
            if (int(scene != nullptr) + int(lod_set != nullptr) + int(instances != nullptr) +
                    int(in_parts != nullptr) >
                1)
              throw std::invalid_argument("render takes one of scene, lod_set and instances (or in_parts)");
            if (splat_budget > 0 && !lod_set)
              throw std::invalid_argument("splat_budget applies to a lod_set");
            settings.splat_budget = splat_budget;
            nb::gil_scoped_release release;
            if (lod_set) return self.renderer->render(*lod_set, camera, settings);
            if (instances) return self.renderer->render(*instances, camera, settings);
            if (in_parts) return self.renderer->render(*in_parts, camera, settings);
            return scene ? self.renderer->render(*scene, camera, settings)
                         : self.renderer->render(camera, settings);
          },
          "camera"_a, "sort"_a = "auto", "depth"_a = true, "splat_count"_a = true, "accuracy"_a = "reference",
          "antialiasing"_a = "classic", "compositor"_a = "sorted", "stochastic_frames"_a = 16, "seed"_a = 1,
          "background"_a = std::array<float, 3>{0, 0, 0}, "reuse_lists"_a = true,
          "near_plane"_a = kDefaultNearPlane, "max_alpha"_a = kDefaultMaxAlpha, "lens"_a = nb::none(),
          "shutter"_a = nb::none(), "scene"_a = nb::none(), "memory_budget"_a = 0, "lod_set"_a = nb::none(),
          "splat_budget"_a = 0, "instances"_a = nb::none(), "region"_a = nb::none(),
          "stochastic_sampler"_a = "hash", "stochastic_accumulate"_a = false, "accumulate_samples"_a = false,
          "mapped_ply"_a = nb::none(), "in_parts"_a = nb::none(),
          "Renders the scene from `camera`: the one set_scene uploaded, or `scene`, which replaces it and is "
          "rendered within memory_budget bytes of device memory (0: the device's own limits), "
          "in depth-ordered parts into the same image where the whole frame would need more "
          "(docs/big-scenes.md); a LodSet `lod_set`: level 0, or under splat_budget the levels this camera "
          "calls for (LodSet.select); SceneInstances `instances`, whose moving models blur under an open "
          "shutter (with or without its end_camera); or a SceneInParts `in_parts` (`mapped_ply`, its "
          "earlier name), in parts decoded as they are drawn. "
          "region (x, y, width, height) renders only those pixels, each the whole frame's to the bit, into "
          "an image of that size (RenderSettings::region). "
          "Keyword arguments are RenderSettings' fields: accuracy is a mode "
          "string ('reference', 'depth16+fp16-sh', ...), antialiasing 'classic', 'antialiased' or 'mip', "
          "compositor 'sorted', 'stochastic' or 'raster' (the depth-sorted splats drawn as quads by the "
          "graphics pipeline); stochastic_sampler 'hash', 'stratified' or 'sobol' (the stochastic "
          "compositor's "
          "thresholds: each splat's stratified over the frames, converging faster); stochastic_accumulate "
          "adds "
          "this call's frames to the previous calls' mean while the view and settings stay the same "
          "(last_frame_stats['accumulated_frames'] counts them); near_plane the view "
          "depth at or below which a Gaussian is "
          "culled; max_alpha the cap on one splat's alpha (0.99 as 3DGS trains, 0.999 as gsplat does); lens "
          "a ThinLens for depth of field (the mean of its samples' pinhole frames in linear light); shutter "
          "a "
          "Shutter for motion blur (the mean of the frames at its times); accumulate_samples renders one "
          "more sample of a 'sobol' lens and shutter a call and returns the mean of the calls' samples while "
          "the view and settings stay the same (last_frame_stats['accumulated_samples'] counts them).")
      .def_prop_ro("last_frame_stats",
                   [](const RendererHandle& self) { return stats_dict(self.renderer->last_frame_stats()); })
      .def_prop_ro("device_info",
                   [](const RendererHandle& self) { return device_dict(self.renderer->device_info()); })
      .def(
          "sort_strategy_for",
          [](const RendererHandle& self, const std::string& requested) {
            return self.renderer->sort_strategy_for(requested);
          },
          "requested"_a,
          "The strategy a requested name stands for on this device ('auto': the one it picks).")
      .def_prop_ro("validation_messages",
                   [](const RendererHandle& self) { return self.renderer->validation_messages(); });
}

}  // namespace tilesplat::python

NB_MODULE(_core, m) {
  tilesplat::python::bind(m);
}
