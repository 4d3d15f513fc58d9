/// @file
/// Cameras in the original trainer's convention (OpenCV axes: x right, y down, z forward): the pinhole,
/// and the lens models real datasets come with (OpenCV distortion, fisheye) and orthographic views.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tilesplat/bounds.h"
#include "tilesplat/export.h"
#include "tilesplat/scene_error.h"

namespace tilesplat {

struct GaussianScene;  // tilesplat/scene.h; the cameras framed on one are defined beside it

/// How a host application's clip space maps onto its image, for Camera::from_matrices(). Both the
/// Vulkan convention and the OpenGL one are named; anything else is a combination of the two fields.
struct ClipSpace {
  /// Where normalized device coordinate y = -1 lands.
  enum class Y {
    kDown,  ///< at the top row: Vulkan's framebuffer with a y-flipped projection (glm: proj[1][1] *= -1)
    kUp,    ///< at the bottom row: OpenGL, and Vulkan drawn with a negative viewport height
  };
  /// The depth range of normalized device coordinates. Only depth images use it (the pinhole camera does
  /// not depend on it); reversed-Z (near maps to 1) and an infinite far plane are read from the matrix.
  enum class Depth {
    kZeroToOne,      ///< Vulkan, Direct3D (glm with GLM_FORCE_DEPTH_ZERO_TO_ONE)
    kMinusOneToOne,  ///< OpenGL
  };
  Y y = Y::kDown;                   ///< which way NDC y runs on the image
  Depth depth = Depth::kZeroToOne;  ///< the NDC depth range

  /// Vulkan with a y-flipped projection: y down, depth 0 to 1.
  static ClipSpace vulkan() { return {Y::kDown, Depth::kZeroToOne}; }
  /// OpenGL: y up, depth -1 to 1.
  static ClipSpace opengl() { return {Y::kUp, Depth::kMinusOneToOne}; }
};

/// How a camera-space point t = (x, y, z) becomes a pixel (Camera::model). Every model keeps the
/// intrinsics' meaning: (cx, cy) is where the optical axis meets the image, fx and fy scale to pixels.
/// A splat goes through a non-linear model by the local Jacobian of the model at its centre (the first
/// order of EWA splatting, as gsplat's fisheye and OpenCV cameras): exact for the mean, an approximation
/// for the shape that grows with the splat's angular size (docs/cameras.md measures it).
enum class CameraModel {
  /// u = fx x / z + cx, v = fy y / z + cy: the trainer's camera and the default.
  kPinhole,
  /// The pinhole with OpenCV's radial-tangential distortion of (x / z, y / z), Camera::distortion =
  /// k1 k2 p1 p2 k3 k4 k5 k6 (OpenCV's order; the rational k4..k6 are 0 for COLMAP's OPENCV). Points
  /// beyond the radius where the radial distortion folds back are not drawn.
  kOpenCV,
  /// Kannala-Brandt, as OpenCV's fisheye module and COLMAP's OPENCV_FISHEYE: theta = the angle from the
  /// optical axis, theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8), and the pixel
  /// lies at radius theta_d (in units of fx, fy) along the point's direction. Zero coefficients are the
  /// equidistant fisheye. Fields of view past 180 degrees: points behind the camera are drawn while
  /// theta_d grows with theta. Camera::distortion = k1 k2 k3 k4 0 0 0 0.
  kFisheye,
  /// u = fx x + cx, v = fy y + cy: parallel rays along the camera's z; fx and fy in pixels per world unit.
  kOrthographic,
  /// Longitude and latitude: u = cx + fx atan2(x, z), v = cy + fy atan2(y, sqrt(x^2 + z^2)), the 360x180
  /// panorama when fx = width / (2 pi), fy = height / pi and (cx, cy) is the image centre
  /// (equirectangular_camera). Longitude 0 is the camera's forward axis, latitude grows downward (y). A
  /// splat across the +-180 degree seam is drawn on both edges; the poles themselves are not drawn.
  kEquirectangular,
};

/// The model's name as files and flags spell it: "pinhole", "opencv", "fisheye", "orthographic",
/// "equirectangular".
TILESPLAT_API const char* camera_model_name(CameraModel model);
/// The model named so (camera_model_name's names); throws std::invalid_argument naming the known ones.
TILESPLAT_API CameraModel parse_camera_model(const std::string& name);

/// A camera: an image size, intrinsics in pixels, a pose, and the model that maps the two (pinhole
/// unless Camera::model says otherwise). Camera space has OpenCV axes
/// (x right, y down, z forward, the convention of the original trainer and COLMAP); pixel (i, j)
/// has its centre at (i + 0.5, j + 0.5), row 0 at the top. A plain value, safe to copy between
/// threads.
struct TILESPLAT_API Camera {
  int width = 0;   ///< image width in pixels
  int height = 0;  ///< image height in pixels
  double fx = 0;   ///< horizontal focal length in pixels
  double fy = 0;   ///< vertical focal length in pixels
  double cx = 0;   ///< principal point x in pixels (the image centre, width / 2, for the trainer's cameras)
  double cy = 0;   ///< principal point y in pixels (height / 2 for the trainer's cameras)
  /// World to camera rotation, row-major 3x3: x_cam = rotation * (x_world - position). Its rows are
  /// the camera's x, y and z axes in world space.
  std::array<double, 9> rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<double, 3> position = {0, 0, 0};  ///< the camera centre in world space
  CameraModel model = CameraModel::kPinhole;   ///< how camera space maps to pixels
  /// The model's coefficients (CameraModel says which); all 0 for the pinhole and the orthographic camera.
  std::array<double, 8> distortion = {0, 0, 0, 0, 0, 0, 0, 0};

  /// A world-space point in camera space: rotation * (world - position).
  std::array<double, 3> to_camera(const std::array<double, 3>& world) const;
  /// Where a world-space point lands on the image through the camera's model, in pixel coordinates
  /// (pixel (i, j) spans [i, i + 1) x [j, j + 1)); std::nullopt where the model draws nothing there (behind
  /// a pinhole, past a lens's fold, at a panorama's poles).
  std::optional<std::array<double, 2>> project(const std::array<double, 3>& world) const;
  /// The world-space unit direction of the ray through pixel coordinates (u, v), the inverse of project();
  /// std::nullopt where no ray lands there (past 180 degrees off a fisheye's axis, past a lens's fold). An
  /// orthographic camera's rays all have its forward axis.
  std::optional<std::array<double, 3>> ray_direction(double u, double v) const;
  /// tan(horizontal fov / 2) = width / (2 fx).
  double tan_half_fov_x() const { return width / (2.0 * fx); }
  /// tan(vertical fov / 2) = height / (2 fy).
  double tan_half_fov_y() const { return height / (2.0 * fy); }

  /// The camera a host application renders with, from its matrices. Both are 4x4, **column-major**
  /// (element (row r, column c) at [c * 4 + r], as glm and OpenGL store them), acting on column vectors:
  /// clip = projection * view * world.
  /// - `view` maps world to view space; it must be rigid (an orthonormal 3x3 block, |R^T R - I| at most 1e-3
  ///   as for every rotation the engine reads; last row 0 0 0 1). The
  ///   view space may be right-handed looking down -z (OpenGL, glm::lookAt) or look down +z (the sign of
  ///   the projection's w row says which); a mirrored view is allowed and renders mirrored.
  /// - `projection` must be a pinhole perspective: clip w = +-view z (row 3 = 0 0 +-k 0), no skew and no
  ///   shift of x or y by w. Off-centre frusta (an asymmetric glm::frustum) become a principal point away
  ///   from the image centre. Standard or reversed-Z, finite or infinite far plane, any depth range.
  /// - `width` and `height` are the image size in pixels; NDC [-1, 1] spans the whole image in x and y.
  ///
  /// The result is the OpenCV-axes camera that renders the same image: its x along the image's columns,
  /// y down its rows, z forward. Throws std::invalid_argument naming what is wrong for a non-finite
  /// element, a view that is not rigid, an orthographic or skewed projection, or a size that is not positive.
  static Camera from_matrices(const std::array<double, 16>& view, const std::array<double, 16>& projection,
                              int width, int height, ClipSpace clip = ClipSpace::vulkan());

  /// Member-wise equality: the same size, intrinsics and pose, to the bit.
  bool operator==(const Camera&) const = default;
};

/// How a host's depth buffer holds depth. A pinhole projection stores, for a point at view depth z
/// (its distance along the camera's forward axis, Camera's z), the window-space depth
/// d = a + b / z that the host's depth test compares: in [0, 1] with Vulkan's viewport depth range
/// 0..1 or OpenGL's glDepthRange(0, 1). Standard (d grows with z, b < 0) and reversed-Z (d falls,
/// b > 0) projections, with a finite or an infinite far plane, all have this form.
struct TILESPLAT_API DepthConvention {
  double a = 1;   ///< the depth of a point at infinity
  double b = -1;  ///< the scale of 1 / z

  /// The convention of a host's projection matrix, column-major as Camera::from_matrices takes it,
  /// in its clip space (ClipSpace::Depth kMinusOneToOne maps NDC [-1, 1] to window [0, 1]).
  /// Throws std::invalid_argument for a projection that is not a pinhole's (clip w not +-view z) or
  /// whose depth does not vary with z.
  static DepthConvention from_projection(const std::array<double, 16>& projection,
                                         ClipSpace clip = ClipSpace::vulkan());

  /// The window depth of view depth z > 0.
  double window_depth(double z) const { return a + b / z; }
  /// The view depth of window depth d; +infinity where d lies at or beyond infinity (the cleared far
  /// value of an infinite projection, say).
  double view_depth(double d) const;
  /// The window depth where the host drew nothing as far as the splats are concerned: a, within [0, 1].
  double far_depth() const;
  /// Member-wise equality.
  bool operator==(const DepthConvention&) const = default;
};

/// Throws std::invalid_argument ("invalid camera: ...", saying what) for a camera no renderer can use:
/// a size that is not positive, focal lengths that are not positive and finite, a non-finite
/// principal point, rotation, position or coefficient, or coefficients the model does not have (any
/// for the pinhole and the orthographic camera, k5..k8 for the fisheye). Both renderers call it;
/// device limits are checked on top.
TILESPLAT_API void validate(const Camera& camera);

/// One entry of the trainer's cameras.json.
struct CameraView {
  int id = 0;        ///< the entry's "id"
  std::string name;  ///< the entry's "img_name": the training image the view reproduces
  Camera camera;     ///< at the file's resolution
};

/// Reads cameras.json. Throws SceneError naming the file and the bad entry.
TILESPLAT_API std::vector<CameraView> load_cameras_json(const std::filesystem::path& path);

/// The same view at another resolution: intrinsics scale with the image size.
/// width or height <= 0 keeps the aspect ratio from the other; both <= 0 keeps the original size.
TILESPLAT_API Camera resize_camera(const Camera& camera, int width, int height);

/// Where orbit_camera() places its camera.
struct OrbitParams {
  double azimuth_deg = 0;        ///< angle around the scene's up axis (-y), in degrees
  double elevation_deg = 20;     ///< angle above the horizontal plane through the centre, in degrees
  double vertical_fov_deg = 50;  ///< vertical field of view, in degrees
  double distance_scale = 1.0;   ///< multiply the framing distance
};
/// A look-at camera on an orbit around the scene's bounds (compute_bounds), looking at their centre
/// with world up = -y, at the distance where their sphere fits the narrower field of view (times
/// OrbitParams::distance_scale). Azimuth 0 is on +z of the centre; positive azimuths turn toward -x.
/// `width` and `height` in pixels. Throws std::invalid_argument for a size that is not positive.
TILESPLAT_API Camera orbit_camera(const GaussianScene& scene, int width, int height,
                                  const OrbitParams& params = {});
/// The same around given bounds (compute_bounds of a scene, or of a scene file's instances).
TILESPLAT_API Camera orbit_camera(const Bounds& bounds, int width, int height,
                                  const OrbitParams& params = {});

/// The camera turned by `radians` (right-handed) about the line through `pivot` along the unit
/// `axis`: its position moves around the line and its axes turn with it, so the scene turns the
/// other way in its view. Orbiting is a pivot at the scene; pivot = camera.position turns it in place.
TILESPLAT_API Camera turn_camera(const Camera& camera, const std::array<double, 3>& pivot,
                                 const std::array<double, 3>& axis, double radians);

/// The equidistant fisheye (CameraModel::kFisheye, zero coefficients) with `camera`'s pose, size and
/// principal point whose `field_of_view_deg` (up to 360) spans the image's shorter side: a circular
/// fisheye inscribed in the frame. Throws std::invalid_argument for a field of view outside (0, 360].
TILESPLAT_API Camera fisheye_camera(const Camera& camera, double field_of_view_deg);

/// The orthographic camera (CameraModel::kOrthographic) with `camera`'s pose, size and principal point
/// whose image is `view_height` world units tall (square pixels). Throws std::invalid_argument for a
/// height that is not positive and finite.
TILESPLAT_API Camera orthographic_camera(const Camera& camera, double view_height);

/// The 360x180 equirectangular panorama (CameraModel::kEquirectangular) with `camera`'s pose and size:
/// fx = width / (2 pi), fy = height / pi, the principal point at the image centre. A 2:1 image has square
/// pixels at the equator.
TILESPLAT_API Camera equirectangular_camera(const Camera& camera);

/// A camera at `eye` looking at `target`; `up` is the world up direction (the camera's -y).
TILESPLAT_API Camera look_at_camera(const std::array<double, 3>& eye, const std::array<double, 3>& target,
                                    const std::array<double, 3>& up, int width, int height,
                                    double vertical_fov_deg);

}  // namespace tilesplat
