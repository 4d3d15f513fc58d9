// The camera paths of tilesplat-bench --accuracy: what each moves and what it keeps.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "accuracy_report.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/scene.h"

namespace {

using tilesplat::Camera;
using tilesplat::accuracy::camera_path;
using tilesplat::accuracy::CameraPath;

Camera start_camera() {
  // Looking at the origin from (3, -1, -4), its up the world's -y (OpenCV axes).
  return tilesplat::look_at_camera({3, -1, -4}, {0, 0, 0}, {0, -1, 0}, 320, 180, 50);
}

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// The angle between the camera axes (rows) of two world-to-camera rotations about their common row `axis`.
double turn_about(const Camera& a, const Camera& b, int row) {
  const int other = row == 1 ? 2 : 1;
  double cosine = 0;
  for (int k = 0; k < 3; ++k) cosine += a.rotation[3 * other + k] * b.rotation[3 * other + k];
  return std::acos(std::min(1.0, cosine));
}

TEST(CameraPath, NamesRoundTrip) {
  for (CameraPath path : {CameraPath::kDolly, CameraPath::kPan, CameraPath::kOrbit})
    EXPECT_EQ(tilesplat::accuracy::parse_camera_path(to_string(path)), path);
  EXPECT_FALSE(tilesplat::accuracy::parse_camera_path("spiral").has_value());
}

TEST(CameraPath, EachPathMovesWhatItSaysAndKeepsTheRest) {
  const Camera start = start_camera();
  const std::array<double, 3> centre = {0, 0, 0};
  const double step = 0.01;
  for (CameraPath kind : {CameraPath::kDolly, CameraPath::kPan, CameraPath::kOrbit}) {
    const auto path = camera_path(kind, start, centre, 4, step);
    ASSERT_EQ(path.size(), 4u);
    EXPECT_EQ(path[0], start) << to_string(kind);
    for (int f = 1; f < 4; ++f) {
      const Camera& c = path[size_t(f)];
      EXPECT_EQ(c.width, start.width);
      EXPECT_EQ(c.fx, start.fx);
      EXPECT_EQ(c.cx, start.cx);
      // The rotation stays a rotation.
      for (int r = 0; r < 3; ++r) {
        double norm = 0;
        for (int k = 0; k < 3; ++k) norm += c.rotation[3 * r + k] * c.rotation[3 * r + k];
        EXPECT_NEAR(norm, 1.0, 1e-12);
      }
      // The camera's y axis (row 1) is the axis every path keeps.
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(c.rotation[3 + k], start.rotation[3 + k], 1e-12) << to_string(kind);
      switch (kind) {
        case CameraPath::kDolly:
          EXPECT_EQ(c.rotation, start.rotation);
          EXPECT_NEAR(distance(c.position, start.position), f * step * distance(start.position, centre), 1e-12);
          break;
        case CameraPath::kPan:
          EXPECT_EQ(c.position, start.position);
          EXPECT_NEAR(turn_about(start, c, 1), f * step, 1e-9);
          break;
        case CameraPath::kOrbit: {
          EXPECT_NEAR(distance(c.position, centre), distance(start.position, centre), 1e-12);
          EXPECT_NEAR(turn_about(start, c, 1), f * step, 1e-9);
          // The scene centre keeps its place in the view: the rig turns about it.
          const auto seen = c.to_camera(centre), seen_from_start = start.to_camera(centre);
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(seen[k], seen_from_start[k], 1e-12);
          break;
        }
      }
    }
  }
}

// The pan turns the camera's coordinates by R_y: x_cam' = R_y(f step) x_cam, R_y = [[c 0 s] [0 1 0] [-s 0 c]].
TEST(CameraPath, PanTurnsCameraCoordinatesAboutY) {
  const Camera start = start_camera();
  const auto path = camera_path(CameraPath::kPan, start, {0, 0, 0}, 3, 0.02);
  for (int f = 1; f < 3; ++f) {
    const double c = std::cos(f * 0.02), s = std::sin(f * 0.02);
    const double turn[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) {
        double expected = 0;
        for (int j = 0; j < 3; ++j) expected += turn[3 * r + j] * start.rotation[3 * j + k];
        EXPECT_NEAR(path[size_t(f)].rotation[3 * r + k], expected, 1e-12) << "frame " << f;
      }
  }
}

TEST(TurnCamera, TurnsAboutTheLineAndBack) {
  const Camera start = start_camera();
  const std::array<double, 3> pivot = {0.5, -0.25, 1}, axis = {0, 0.6, 0.8};
  const Camera turned = tilesplat::turn_camera(start, pivot, axis, 0.3);
  // A point on the line keeps its place in the view; the camera keeps its distance to the line's points.
  const std::array<double, 3> on_line = {pivot[0] + 2 * axis[0], pivot[1] + 2 * axis[1], pivot[2] + 2 * axis[2]};
  for (const auto& point : {pivot, on_line}) {
    const auto before = start.to_camera(point), after = turned.to_camera(point);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(after[k], before[k], 1e-12);
  }
  EXPECT_NEAR(distance(turned.position, pivot), distance(start.position, pivot), 1e-12);
  const Camera back = tilesplat::turn_camera(turned, pivot, axis, -0.3);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(back.position[k], start.position[k], 1e-12);
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(back.rotation[k], start.rotation[k], 1e-12);
  // Turning in place about the view axis is a roll: the position stays, the view axis too.
  const std::array<double, 3> forward = {start.rotation[6], start.rotation[7], start.rotation[8]};
  const Camera rolled = tilesplat::turn_camera(start, start.position, forward, 0.5);
  EXPECT_EQ(rolled.position, start.position);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(rolled.rotation[6 + k], forward[k], 1e-12);
}

// The view-consistency pair in the exact ray order: the report's figure is that pair's, rendered by the
// float64 reference at twice the view's size and turned in place as the reference's own pair is.
TEST(AccuracyReport, MeasuresTheExactRayOrdersViewConsistency) {
  using namespace tilesplat;
  const GaussianScene scene = load_scene(tilesplat::testing::bundled_sh3());
  const Camera view = orbit_camera(scene, 64, 36);
  accuracy::Options options;
  options.modes = {AccuracyModes{}};
  options.views = {view};
  options.view_names = {"view 0"};
  options.warmup = 0;
  options.repeat = 1;
  options.path_frames = 0;
  options.consistency_angle = 0.05;
  int steps = 0, total = 0;
  const accuracy::SceneReport report = accuracy::measure_scene(
      tilesplat::testing::validated_renderer(), scene, options, [&](int done, int of, const std::string&) {
        steps = done;
        total = of;
      });
  EXPECT_EQ(steps, total);
  EXPECT_EQ(total, accuracy::work_units(options, scene.sh_degree));

  const std::vector<Camera> turned =
      camera_path(CameraPath::kPan, resize_camera(view, 128, 72), {}, 2, options.consistency_angle);
  RenderSettings settings;
  settings.splat_count = false;
  auto pair_inconsistency = [&](ReferenceOrder order) {
    return rotation_inconsistency(render_reference(scene, turned[0], settings, order), turned[0],
                                  render_reference(scene, turned[1], settings, order), turned[1],
                                  accuracy::kConsistencyBlock, accuracy::kConsistencyThreshold);
  };
  const TemporalDifference exact = pair_inconsistency(ReferenceOrder::kRayDepth);
  const TemporalDifference centre = pair_inconsistency(ReferenceOrder::kSettings);
  EXPECT_EQ(report.exact_order_inconsistency, exact.flicker_fraction);
  EXPECT_EQ(report.exact_order_inconsistency_mean, exact.mean_abs);
  EXPECT_EQ(report.reference_inconsistency_mean, centre.mean_abs);
  // The two orders differ on this scene, so the figure is not the centre-depth order's again.
  EXPECT_NE(exact.mean_abs, centre.mean_abs);
  EXPECT_NE(accuracy::text_table(report).find("(in the exact ray order "), std::string::npos)
      << accuracy::text_table(report);
}

}  // namespace
