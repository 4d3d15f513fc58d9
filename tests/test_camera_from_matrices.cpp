// Camera::from_matrices: the view and projection matrices a host builds, in every convention hosts
// use, give back the cameras.json camera they were built from, and render its image to the bit.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

using Matrix = std::array<double, 16>;

// Column-major, as glm stores them: element (row, column) at [column * 4 + row].
double& at(Matrix& m, int row, int column) {
  return m[size_t(column) * 4 + size_t(row)];
}

// How a host lays out its view space and clip space.
struct Convention {
  std::string name;
  bool looks_down_minus_z;  // OpenGL / glm::lookAt view space (x right, y up, -z forward); else OpenCV's
  ClipSpace clip;
  bool reversed_z;
  bool infinite_far;
};

// The host's view matrix of a camera: its axes as rows, signed for the view space's convention.
Matrix view_matrix(const Camera& camera, bool looks_down_minus_z) {
  const double signs[3] = {1, looks_down_minus_z ? -1.0 : 1.0, looks_down_minus_z ? -1.0 : 1.0};
  Matrix view{};
  for (int row = 0; row < 3; ++row) {
    double translation = 0;
    for (int column = 0; column < 3; ++column) {
      at(view, row, column) = signs[row] * camera.rotation[size_t(row) * 3 + size_t(column)];
      translation -= at(view, row, column) * camera.position[size_t(column)];
    }
    at(view, row, 3) = translation;
  }
  at(view, 3, 3) = 1;
  return view;
}

// The host's projection of a camera's intrinsics, written out as glm::perspective / glm::frustum and
// their reversed-Z and infinite variants write them.
Matrix projection_matrix(const Camera& camera, const Convention& convention, double near, double far) {
  const double w = camera.width, h = camera.height;
  const double forward = convention.looks_down_minus_z ? -1.0 : 1.0;  // clip w = forward * z_view
  // Up-pointing view y (OpenGL view space) with NDC y down needs the y flip, and vice versa.
  const bool view_y_up = convention.looks_down_minus_z;
  const bool ndc_y_down = convention.clip.y == ClipSpace::Y::kDown;
  const double y_flip = view_y_up == ndc_y_down ? -1.0 : 1.0;
  Matrix p{};
  at(p, 0, 0) = 2 * camera.fx / w;
  at(p, 0, 2) = forward * (2 * camera.cx / w - 1);
  at(p, 1, 1) = y_flip * 2 * camera.fy / h;
  at(p, 1, 2) = forward * (ndc_y_down ? 1.0 : -1.0) * (2 * camera.cy / h - 1);
  at(p, 3, 2) = forward;
  // Depth: NDC z of the near plane is 0 (or -1) and of the far plane 1; reversed-Z swaps them.
  const bool zero_to_one = convention.clip.depth == ClipSpace::Depth::kZeroToOne;
  double a, b;  // ndc_z = (a z_forward + b) / z_forward
  if (convention.infinite_far) {
    a = convention.reversed_z ? 0.0 : 1.0;
    b = convention.reversed_z ? near : (zero_to_one ? -near : -2 * near);
    if (!zero_to_one && convention.reversed_z) a = -1.0, b = 2 * near;
  } else {
    const double lo = zero_to_one ? 0.0 : -1.0;
    const double z_near = convention.reversed_z ? 1.0 : lo, z_far = convention.reversed_z ? lo : 1.0;
    a = (z_far * far - z_near * near) / (far - near);
    b = (z_near - z_far) * near * far / (far - near);
  }
  at(p, 2, 2) = forward * a;
  at(p, 2, 3) = b;
  return p;
}

const std::vector<Convention>& conventions() {
  static const std::vector<Convention> all = {
      {"OpenGL (glm::perspective)", true, ClipSpace::opengl(), false, false},
      {"OpenGL, infinite far", true, ClipSpace::opengl(), false, true},
      {"OpenGL, reversed-Z", true, ClipSpace::opengl(), true, false},
      {"Vulkan, y-flipped projection", true, ClipSpace::vulkan(), false, false},
      {"Vulkan, reversed-Z", true, ClipSpace::vulkan(), true, false},
      {"Vulkan, reversed-Z, infinite far", true, ClipSpace::vulkan(), true, true},
      {"Vulkan, negative viewport height",
       true,
       {ClipSpace::Y::kUp, ClipSpace::Depth::kZeroToOne},
       false,
       false},
      {"OpenCV view space (+z forward, y down)", false, ClipSpace::vulkan(), false, false},
      {"OpenCV view space, reversed-Z, infinite far", false, ClipSpace::vulkan(), true, true},
  };
  return all;
}

void expect_same_camera(const Camera& got, const Camera& expected, const std::string& what) {
  EXPECT_EQ(got.width, expected.width) << what;
  EXPECT_EQ(got.height, expected.height) << what;
  const auto near = [&](double a, double b, const char* field) {
    EXPECT_NEAR(a, b, 1e-12 * std::max(1.0, std::fabs(b))) << what << ": " << field;
  };
  near(got.fx, expected.fx, "fx");
  near(got.fy, expected.fy, "fy");
  near(got.cx, expected.cx, "cx");
  near(got.cy, expected.cy, "cy");
  for (size_t i = 0; i < 9; ++i)
    EXPECT_EQ(got.rotation[i], expected.rotation[i]) << what << ": rotation " << i;
  for (size_t i = 0; i < 3; ++i) near(got.position[i], expected.position[i], "position");
}

// Every convention, two views, a centred and an off-centre principal point: the same camera, and the
// same image to the bit.
TEST(CameraFromMatrices, EveryConventionGivesTheCamerasJsonCameraAndItsImage) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const auto views = load_cameras_json(testing::bundled_playbot_cameras());
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  for (const size_t v : {size_t{1}, size_t{5}}) {
    for (const bool off_centre : {false, true}) {
      Camera camera = resize_camera(views.at(v).camera, 160, 90);
      if (off_centre) {
        camera.cx += 13.5;
        camera.cy -= 7.25;
      }
      const RenderImage expected = renderer.render(camera);
      for (const Convention& convention : conventions()) {
        const std::string what =
            "view " + std::to_string(v) + (off_centre ? " off-centre, " : ", ") + convention.name;
        const Camera from = Camera::from_matrices(view_matrix(camera, convention.looks_down_minus_z),
                                                  projection_matrix(camera, convention, 0.05, 300.0),
                                                  camera.width, camera.height, convention.clip);
        expect_same_camera(from, camera, what);
        const RenderImage image = renderer.render(from);
        EXPECT_EQ(image.rgba, expected.rgba) << what;
        EXPECT_EQ(image.depth, expected.depth) << what;
      }
    }
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// A projection check independent of the construction above: a world point projected by the host's
// matrices lands on the pixel the camera puts it on.
TEST(CameraFromMatrices, HostProjectionOfAPointLandsWhereTheCameraPutsIt) {
  Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(2).camera, 320, 180);
  camera.cx = 150;
  camera.cy = 100;
  const std::array<double, 3> point = {0.1, -0.2, 0.3};
  const auto cam = camera.to_camera(point);
  const double px = camera.cx + camera.fx * cam[0] / cam[2], py = camera.cy + camera.fy * cam[1] / cam[2];
  for (const Convention& convention : conventions()) {
    const Matrix view = view_matrix(camera, convention.looks_down_minus_z);
    const Matrix projection = projection_matrix(camera, convention, 0.1, 100.0);
    double clip[4] = {0, 0, 0, 0}, eye[4] = {0, 0, 0, 0};
    const double world[4] = {point[0], point[1], point[2], 1};
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) eye[r] += view[size_t(c) * 4 + size_t(r)] * world[c];
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) clip[r] += projection[size_t(c) * 4 + size_t(r)] * eye[c];
    const double ndc_x = clip[0] / clip[3], ndc_y = clip[1] / clip[3], ndc_z = clip[2] / clip[3];
    const bool down = convention.clip.y == ClipSpace::Y::kDown;
    EXPECT_NEAR(camera.width / 2.0 * (1 + ndc_x), px, 1e-9) << convention.name;
    EXPECT_NEAR(camera.height / 2.0 * (down ? 1 + ndc_y : 1 - ndc_y), py, 1e-9) << convention.name;
    const double lo = convention.clip.depth == ClipSpace::Depth::kZeroToOne ? 0.0 : -1.0;
    EXPECT_GT(ndc_z, lo) << convention.name;  // the point is between the planes (depth rows are right)
    EXPECT_LT(ndc_z, 1.0) << convention.name;
  }
}

TEST(CameraFromMatrices, NonPinholeAndBrokenMatricesAreRejectedNamingWhy) {
  Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, 64, 36);
  const Convention& gl = conventions().front();
  const Matrix view = view_matrix(camera, true);
  const Matrix projection = projection_matrix(camera, gl, 0.1, 100.0);
  const auto error = [&](Matrix v, Matrix p, int width = 64, int height = 36) {
    return tilesplat::testing::error_of<std::invalid_argument>(
        [&] { Camera::from_matrices(v, p, width, height, gl.clip); });
  };
  const auto has = [](const std::string& message, const std::string& part) {
    return message.find(part) != std::string::npos;
  };

  Matrix orthographic{};
  at(orthographic, 0, 0) = 0.1;
  at(orthographic, 1, 1) = 0.1;
  at(orthographic, 2, 2) = -0.02;
  at(orthographic, 3, 3) = 1;
  EXPECT_TRUE(has(error(view, orthographic), "orthographic")) << error(view, orthographic);
  Matrix skewed = projection;
  at(skewed, 0, 1) = 0.2;
  EXPECT_TRUE(has(error(view, skewed), "skewed")) << error(view, skewed);
  Matrix shifted = projection;
  at(shifted, 0, 3) = 0.5;
  EXPECT_TRUE(has(error(view, shifted), "shifts x or y")) << error(view, shifted);
  Matrix mixed_w = projection;
  at(mixed_w, 3, 0) = 0.3;
  EXPECT_TRUE(has(error(view, mixed_w), "w row")) << error(view, mixed_w);
  Matrix scaled = view;
  for (int c = 0; c < 3; ++c) at(scaled, 0, c) *= 2;
  EXPECT_TRUE(has(error(scaled, projection), "not rigid")) << error(scaled, projection);
  Matrix last_row = view;
  at(last_row, 3, 0) = 1;
  EXPECT_TRUE(has(error(last_row, projection), "last row")) << error(last_row, projection);
  Matrix nan_view = view;
  at(nan_view, 1, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error(nan_view, projection), "Camera::from_matrices: view(1, 3) is not finite");
  Matrix inf_projection = projection;
  at(inf_projection, 2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error(view, inf_projection), "Camera::from_matrices: projection(2, 2) is not finite");
  EXPECT_EQ(error(view, projection, 0, 36), "Camera::from_matrices: image size 0x36 is not positive");
  Matrix zero_x = projection;
  at(zero_x, 0, 0) = 0;
  EXPECT_TRUE(has(error(view, zero_x), "zero on its diagonal")) << error(view, zero_x);

  // A view built in float (as most hosts build it) is rigid to float precision, and accepted.
  Matrix float_view = view;
  for (double& value : float_view) value = double(float(value));
  EXPECT_NO_THROW(Camera::from_matrices(float_view, projection, 64, 36, gl.clip));
}

// A view matrix's 3x3 block follows the rule every rotation the engine reads follows
// (camera/rotation_check.h): |R^T R - I| at most 1e-3. A host's float rounding passes and so does a
// file's few digits; a real scale of the scene does not. A mirror is a host's to make, and passes.
TEST(CameraFromMatrices, TheViewsBlockFollowsTheOneRotationRule) {
  Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, 64, 36);
  const Convention& gl = conventions().front();
  const Matrix view = view_matrix(camera, true);
  const Matrix projection = projection_matrix(camera, gl, 0.1, 100.0);
  const auto scaled_row = [&](double factor) {
    Matrix scaled = view;
    for (int c = 0; c < 3; ++c) at(scaled, 0, c) *= factor;
    return scaled;
  };
  // (1 + e)^2 - 1 is about 2e: 4e-4 off, within the tolerance; 2.2e-3 off, past it.
  EXPECT_NO_THROW(Camera::from_matrices(scaled_row(1.0002), projection, 64, 36, gl.clip));
  const std::string refused = tilesplat::testing::error_of<std::invalid_argument>(
      [&] { Camera::from_matrices(scaled_row(1.0011), projection, 64, 36, gl.clip); });
  EXPECT_NE(refused.find("not rigid: its 3x3 block is not orthonormal"), std::string::npos) << refused;
  EXPECT_NE(refused.find("tolerance 0.001"), std::string::npos) << refused;
  Matrix mirrored = view;
  for (int c = 0; c < 4; ++c) at(mirrored, 0, c) = -at(mirrored, 0, c);
  EXPECT_NO_THROW(Camera::from_matrices(mirrored, projection, 64, 36, gl.clip));
}

}  // namespace
}  // namespace tilesplat
