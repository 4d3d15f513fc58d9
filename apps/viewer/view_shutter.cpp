#include "view_shutter.h"

namespace tilesplat::viewer {

ViewShutter::ViewShutter(const Shutter& shutter, const Camera& view_camera)
    : shutter_(shutter), camera_moves_(shutter.end_camera.has_value()) {
  shutter_.end_camera.reset();
  shutter_.pattern = SamplePattern::kSobol;
  if (!camera_moves_) return;
  const Camera& end = *shutter.end_camera;
  const std::array<double, 9>& start_r = view_camera.rotation;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double sum = 0;  // (R_end R_start^T)_ij: row i of R_end against row j of R_start
      for (int k = 0; k < 3; ++k) sum += end.rotation[3 * i + k] * start_r[3 * j + k];
      turn_[3 * i + j] = sum;
    }
  for (int i = 0; i < 3; ++i) {
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += start_r[3 * i + k] * (end.position[k] - view_camera.position[k]);
    shift_[i] = sum;
  }
}

Shutter ViewShutter::for_camera(const Camera& camera) const {
  Shutter shutter = shutter_;
  if (!camera_moves_) return shutter;
  // The end camera: its axes turned from the camera's as the view's end from its start
  // (R_end' = turn R_camera), its centre moved by the shift in the camera's axes (p_camera + R_camera^T
  // shift).
  Camera end = camera;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double sum = 0;
      for (int k = 0; k < 3; ++k) sum += turn_[3 * i + k] * camera.rotation[3 * k + j];
      end.rotation[3 * i + j] = sum;
    }
  for (int j = 0; j < 3; ++j) {
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += camera.rotation[3 * k + j] * shift_[k];
    end.position[j] = camera.position[j] + sum;
  }
  shutter.end_camera = end;
  return shutter;
}

}  // namespace tilesplat::viewer
