/// @file
/// Scene descriptions: a JSON file that composes several splat files into one scene, each placed by a
/// model transform, with the cameras, background, effects and outputs to render it with.
/// The format is documented in docs/scene-format.md (JSON Schema: docs/scene.schema.json).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"
#include "tilesplat/shutter.h"

namespace tilesplat {

/// Places one splat file in the scene: p' = s R p + t, applied after the optional z_up conversion.
struct TILESPLAT_API ModelTransform {
  std::array<double, 3> translation = {0, 0, 0};  ///< t, in world units
  /// Unit quaternion w x y z. In JSON, "quaternion": [w, x, y, z] or "rotation_deg": [rx, ry, rz].
  std::array<double, 4> rotation = {1, 0, 0, 0};
  /// Must be uniform (all three equal, positive): transform_scene rejects anything else. Three values
  /// so that a non-uniform scale can be written down, and refused with the reason, not truncated.
  std::array<double, 3> scale = {1, 1, 1};
  /// The capture's up axis is +Z (Blender, many photogrammetry tools). The engine's world follows the
  /// trainer's OpenCV/COLMAP convention, whose up is -Y (cameras: x right, y down, z forward), so z_up
  /// first rotates the capture by +90 degrees about +X: (x, y, z) -> (x, -z, y), taking +Z to -Y.
  bool z_up = false;

  /// Whether the transform changes nothing: no translation, rotation, scale or z_up.
  bool is_identity() const;
};

/// The transform at time `t` in [0, 1] of a model that moves from `start` (time 0) to `end` (time 1) while
/// a frame's shutter is open (RenderSettings::shutter, docs/effects.md "Moving models"): translation and
/// scale blended linearly, the rotation by the shortest-arc slerp, z_up start's. Exactly `start` at 0 and
/// `end` at 1. Throws std::invalid_argument for t outside [0, 1], an invalid transform (validate) or an
/// `end` whose z_up differs.
TILESPLAT_API ModelTransform transform_between(const ModelTransform& start, const ModelTransform& end,
                                               double t);

/// The rotation z_up applies: +90 degrees about +X, as a w x y z quaternion.
TILESPLAT_API std::array<double, 4> z_up_rotation();

/// Euler angles in degrees, extrinsic X then Y then Z (about the world axes): R = Rz Ry Rx.
TILESPLAT_API std::array<double, 4> quaternion_from_euler_xyz_deg(const std::array<double, 3>& degrees);

/// Row-major 3x3 matrix of a unit quaternion w x y z (the convention of the scene's rotations).
TILESPLAT_API std::array<double, 9> rotation_matrix(const std::array<double, 4>& quaternion);

/// Everything the transform rotates by, z_up included: rotation * z_up_rotation() when z_up.
TILESPLAT_API std::array<double, 4> total_rotation(const ModelTransform& transform);

/// Throws std::invalid_argument when the transform cannot be applied exactly: a non-finite value, a
/// quaternion whose norm is not 1 (within 1e-3), a scale that is not positive, or a non-uniform scale.
TILESPLAT_API void validate(const ModelTransform& transform);

/// Exact rotation of real spherical harmonics, in the basis and signs of eval_sh (tilesplat/reference.h):
/// coefficients c' with eval_sh(c', R d) == eval_sh(c, d) for every direction d. Band l's (2l+1)x(2l+1)
/// matrix is fitted once per rotation from eval_sh itself, so it cannot drift from the renderers' basis.
class TILESPLAT_API ShRotation {
 public:
  explicit ShRotation(const std::array<double, 9>& rotation);  ///< row-major, a proper rotation
  /// One Gaussian's coefficients: (degree + 1)^2 * 3 floats, coefficient-major, RGB innermost.
  void apply(int degree, float* coefficients) const;
  /// Band l (1..3), row-major: the band's new coefficients are this matrix times the old ones.
  std::span<const double> band(int l) const;

 private:
  std::array<std::vector<double>, 4> bands_;
};

/// The scene placed by the transform: positions p' = s R p + t; rotations q' = q_R q (normalised);
/// log scales + log s; SH bands 1..3 rotated exactly (ShRotation); normals rotated. A transform
/// without rotation leaves rotations, SH and normals bit-identical; the identity leaves everything so.
/// Throws std::invalid_argument for an invalid transform (validate), above all a non-uniform scale,
/// or when a transformed value overflows float.
TILESPLAT_API GaussianScene transform_scene(const GaussianScene& scene, const ModelTransform& transform);

/// The camera that sees transform_scene(scene, transform) as `camera` sees `scene`: centre moved by
/// the transform, axes rotated with it. The images agree (depths scale by s). Throws
/// std::invalid_argument for an invalid transform (validate).
TILESPLAT_API Camera transform_camera(const Camera& camera, const ModelTransform& transform);

/// The same Gaussians with `degree` (0..3) SH bands: higher bands dropped, missing ones zero.
TILESPLAT_API GaussianScene with_sh_degree(const GaussianScene& scene, int degree);

/// All Gaussians of all scenes, in order. The result's SH degree is the largest; scenes of lower
/// degree get zero coefficients (the same colours). Normals are kept when any scene has them (zero
/// for those without). Throws std::invalid_argument for a scene whose arrays disagree in size.
TILESPLAT_API GaussianScene merge_scenes(std::span<const GaussianScene> scenes);

/// One splat file of a scene description and where it is placed.
struct SceneModel {
  std::filesystem::path path;  ///< resolved: relative paths in the file are relative to its directory
  ModelTransform transform;    ///< where the file's Gaussians go in the scene (at time 0)
  /// Where they are at time 1, the model's "motion" in the file: it moves between the two while a
  /// camera's shutter is open (transform_between). None: it stays at `transform`.
  std::optional<ModelTransform> motion;
};

/// A light of a scene description's relighting effect, as the file gives it (tilesplat::Light has the model).
struct SceneLight {
  /// A light at infinity or at a point.
  enum class Type {
    kDirectional,  ///< "directional": parallel light along `direction`
    kPoint,        ///< "point": light from `position`
  };
  Type type = Type::kDirectional;               ///< which of the two
  std::array<double, 3> direction = {0, 1, 0};  ///< directional: where the light travels (unit length)
  std::array<double, 3> position = {0, 0, 0};   ///< point
  std::array<double, 3> color = {1, 1, 1};      ///< RGB factor on the trained colour (docs/colour.md)
  double intensity = 1;                         ///< >= 0
};

/// Each effect is off unless the file asks for it.
struct SceneEffects {
  /// Cap on the SH degree evaluated (0..3); none: every band the files have. "view_dependent": false
  /// in the file means 0 (the DC colour alone).
  std::optional<int> sh_degree;
  Antialiasing antialiasing = Antialiasing::kClassic;  ///< the footprint filter the assets were trained with
  std::vector<SceneLight> lights;             ///< relighting (tilesplat::Lighting has the model); none: unlit
  std::array<double, 3> ambient = {0, 0, 0};  ///< relighting's ambient factor, RGB (only with lights)
  double exposure_stops = 0;                  ///< PNG previews: colours times 2^exposure (PreviewOptions)
  ToneMap tone_map = ToneMap::kNone;          ///< PNG previews (PreviewOptions)
};

/// What a render writes. Colour is always written; the rest as listed in the file's "outputs".
struct SceneOutputs {
  bool color = true;         ///< RGB (always written)
  bool alpha = true;         ///< the A channel (1 - T)
  bool depth = false;        ///< the expected depth, as the EXR's Z channel
  bool splat_count = false;  ///< the per-pixel blended-splat count
};

/// A scene description file, read and checked (load_scene_description()); paths resolved.
struct SceneDescription {
  std::filesystem::path file;          ///< the description itself (names it in error messages)
  std::vector<SceneModel> models;      ///< the splat files, in order (load_described_scene() merges them)
  std::vector<CameraView> cameras;     ///< empty when the file has none
  /// The lens each camera looks through (a camera's "lens": depth of field, tilesplat/lens.h): one per
  /// camera, off (aperture 0) where a camera has none; empty when the cameras come from a cameras.json.
  std::vector<ThinLens> lenses;
  /// The shutter each camera exposes through (a camera's "shutter": motion blur, tilesplat/shutter.h): one
  /// per camera, closed where a camera has none; empty when the cameras come from a cameras.json. Its
  /// end_camera is unset for a camera that stays still (the moving models still blur).
  std::vector<Shutter> shutters;
  std::filesystem::path cameras_file;  ///< resolved cameras.json when "cameras" names one, else empty
  std::array<float, 3> background = {0, 0, 0};  ///< RGB behind the splats, display values like theirs
  SceneEffects effects;                         ///< what to simulate; each off unless the file asks
  SceneOutputs outputs;                         ///< which images to write
};

/// Reads a scene description. Throws SceneError for every mistake, as
/// "FILE: JSON.PATH: what is wrong, what is allowed" (e.g. "scene.json: effects.lights[1].type: ..."),
/// or "FILE: line L, column C: malformed JSON: ..." for a syntax error. Referenced files must exist.
TILESPLAT_API SceneDescription load_scene_description(const std::filesystem::path& path);

/// The same on text already in memory; `file` names it in messages and anchors relative paths.
TILESPLAT_API SceneDescription parse_scene_description(std::string_view text,
                                                       const std::filesystem::path& file);

/// Loads every model (load_scene), transforms and merges them, keeping only the SH bands the
/// description's sh_degree effect evaluates. Throws SceneError naming the description,
/// the model and the problem. The report sums the files' reports.
TILESPLAT_API GaussianScene load_described_scene(const SceneDescription& description,
                                                 const LoadOptions& options = {},
                                                 LoadReport* report = nullptr);

/// A scene description's models as placed copies of the files they name, each file's Gaussians held
/// once: the scene load_described_scene() merges, without the merged copy. Renderer::render takes it
/// under a memory budget and places the copies part by part (docs/big-scenes.md), so that a scene of
/// many copies needs host memory for its files only.
struct TILESPLAT_API SceneInstances {
  /// One placed copy: a file's Gaussians through a transform.
  struct TILESPLAT_API Instance {
    size_t file = 0;           ///< index into `files`
    ModelTransform transform;  ///< where the copy goes (transform_scene), at time 0
    /// Where it goes at time 1 (SceneModel::motion); none for a copy that stays put.
    std::optional<ModelTransform> end_transform;
    /// Its transform at time `t` in [0, 1]: `transform`, or transform_between it and end_transform.
    ModelTransform at(double t) const;
  };
  std::vector<GaussianScene> files;  ///< each file the description names, once, as load_scene read it
  std::vector<Instance> instances;   ///< the models in the description's order: the merged scene's order
  int sh_degree = 0;     ///< the merged scene's SH degree (the largest, capped by the sh_degree effect)
  bool normals = false;  ///< whether the merged scene has normals (any file has them)

  /// The merged scene's Gaussians: the sum over the instances.
  size_t size() const;
  /// Whether any instance moves (has an end_transform): then Renderer::render blurs its motion over an
  /// open shutter (RenderSettings::shutter), the camera still or moving.
  bool moves() const;
};

/// Loads every file the description names once and places its models as instances (what
/// load_described_scene merges). Throws as load_described_scene does; the report sums the models'.
TILESPLAT_API SceneInstances load_scene_instances(const SceneDescription& description,
                                                  const LoadOptions& options = {},
                                                  LoadReport* report = nullptr);

/// The instances transformed and merged, in order: load_described_scene's scene, bit for bit.
TILESPLAT_API GaussianScene merge_instances(const SceneInstances& scene);
/// The same with each instance where it is at time `t` in [0, 1] (Instance::at): at 0,
/// merge_instances(scene).
TILESPLAT_API GaussianScene merge_instances(const SceneInstances& scene, double t);

/// The bounds of the merged scene (compute_bounds of merge_instances(scene)), from the placed positions
/// alone.
TILESPLAT_API Bounds compute_bounds(const SceneInstances& scene);

/// Whether the path names a scene description (a .json file) rather than a splat file.
TILESPLAT_API bool is_scene_description(const std::filesystem::path& path);

}  // namespace tilesplat
