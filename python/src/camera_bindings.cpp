// Cameras for Python: tilesplat.Camera (the pinhole and the other models), the views of camera sets,
// orbits and keyframed paths.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>

#include "bindings.h"
#include "tilesplat/camera.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/camera_sets.h"
#include "tilesplat/scene.h"

namespace tilesplat::python {

using namespace nb::literals;

void bind_cameras(nb::module_& m) {
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
}

}  // namespace tilesplat::python
