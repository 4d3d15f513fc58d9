/// @file
/// Camera sets where datasets keep them: the trainer's cameras.json (load_cameras_json in camera.h),
/// COLMAP sparse models and nerfstudio / instant-ngp transforms.json. Every reader returns the views
/// in the engine's convention (world-to-camera rotation, camera x right, y down, z forward).
#pragma once

#include <filesystem>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"

namespace tilesplat {

/// A COLMAP sparse model: `path` is its folder (holding cameras.bin and images.bin, or cameras.txt
/// and images.txt; a dataset root whose sparse/0 holds them works too) or one of those files.
/// The views are the registered images sorted by name, as the 3DGS trainer orders them; a view's id
/// is the COLMAP image id and its name the image name. PINHOLE and SIMPLE_PINHOLE cameras are read
/// with their principal point; any other camera model (they all model lens distortion) is an error
/// naming the model, since the renderer draws undistorted pinhole images (undistort first:
/// `colmap image_undistorter`). Throws SceneError naming the file for a missing, truncated or
/// malformed model, an image whose camera is not in cameras, or non-finite values.
TILESPLAT_API std::vector<CameraView> load_colmap_cameras(const std::filesystem::path& path);

/// A nerfstudio or instant-ngp transforms.json: intrinsics at the top level (fl_x, fl_y, cx, cy,
/// w, h, or camera_angle_x with w and h) which a frame may override, and per frame a 4x4
/// camera-to-world `transform_matrix` in the OpenGL convention (x right, y up, z backward), turned
/// into the engine's as the 3DGS trainer does (the y and z axes negated). The views keep the file's
/// order; a view's name is its file_path, its id its position. A distortion coefficient other than
/// zero (k1..k4, p1, p2) or a camera_model other than OPENCV/PINHOLE is an error naming it.
/// instant-ngp's scale, offset and aabb_scale are not applied (as the 3DGS trainer does not).
/// Throws SceneError naming the file and the frame.
TILESPLAT_API std::vector<CameraView> load_transforms_json(const std::filesystem::path& path);

/// Any of the three, told apart by the path: a folder or a .bin/.txt file is a COLMAP model, a
/// JSON object with "frames" a transforms.json, a JSON array the trainer's cameras.json.
/// Throws SceneError as the reader it picks.
TILESPLAT_API std::vector<CameraView> load_camera_set(const std::filesystem::path& path);

}  // namespace tilesplat
