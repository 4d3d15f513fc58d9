// Camera models (tilesplat::CameraModel): OpenCV distortion, the Kannala-Brandt fisheye (past 180
// degrees) and the orthographic camera on the GPU against the float64 reference, each against the
// pinhole image it must reproduce where the two see the same rays (resampled), and the pinhole's own
// frame left as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

using namespace tilesplat;

namespace {

// A COLMAP OPENCV camera's coefficients as a phone's wide lens has them (barrel, a little tangential).
Camera opencv_camera(const Camera& pinhole) {
  Camera camera = pinhole;
  camera.model = CameraModel::kOpenCV;
  camera.distortion = {-0.12, 0.03, 0.001, -0.0015, 0, 0, 0, 0};
  return camera;
}

// Opaque, differently coloured Gaussians of a few pixels on a shell of radius 4 to 6 around the origin: a
// smooth image from a camera at the origin, whatever its model, so that resampling one model's image
// into another's costs little and what differs is the model.
GaussianScene smooth_shell() {
  GaussianScene scene;
  uint32_t state = 12345;
  auto uniform = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);
  };
  for (int i = 0; i < 20000; ++i) {
    const double z = 2 * uniform() - 1, phi = 2 * std::numbers::pi * uniform();
    const double r = std::sqrt(1 - z * z), distance = 4 + 2 * uniform();
    for (const double v : {r * std::cos(phi) * distance, r * std::sin(phi) * distance, z * distance})
      scene.positions.push_back(float(v));
    for (int k = 0; k < 3; ++k) scene.log_scales.push_back(float(std::log(0.12 + 0.08 * uniform())));
    for (const double q : {1.0, uniform() - 0.5, uniform() - 0.5, uniform() - 0.5})
      scene.rotations.push_back(float(q));
    scene.opacity_logits.push_back(3.0f);
    for (int c = 0; c < 3; ++c) scene.sh.push_back(float((uniform() - 0.5) / 0.28209479177387814));
  }
  return scene;
}

// Round opaque Gaussians of radius `scale` on the sphere of radius 5 about the origin, at the
// directions of a Fibonacci lattice, far enough apart that none blends into another: an image whose
// pixels do not depend on the order splats blend in (a fisheye sorts by distance, a pinhole by z).
GaussianScene separated_blobs(int count, double scale) {
  GaussianScene scene;
  const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1 - 2 * (i + 0.5) / count, r = std::sqrt(1 - z * z), phi = golden * i;
    for (const double v : {5 * r * std::cos(phi), 5 * r * std::sin(phi), 5 * z})
      scene.positions.push_back(float(v));
    for (int k = 0; k < 3; ++k) scene.log_scales.push_back(float(std::log(scale)));
    for (const double q : {1.0, 0.0, 0.0, 0.0}) scene.rotations.push_back(float(q));
    scene.opacity_logits.push_back(3.0f);
    for (int c = 0; c < 3; ++c)
      scene.sh.push_back(float((0.3 * std::sin(1.7 * i + 2.1 * c)) / 0.28209479177387814));
  }
  return scene;
}

// Bilinear lookup of an RGBA image at pixel coordinates (u, v) (centres at +0.5); false outside.
bool sample_rgba(const RenderImage& image, double u, double v, float out[4]) {
  const double x = u - 0.5, y = v - 0.5;
  if (!(x >= 0 && y >= 0 && x <= image.width - 1 && y <= image.height - 1)) return false;
  const int x0 = std::min(int(x), image.width - 2), y0 = std::min(int(y), image.height - 2);
  const double fx = x - x0, fy = y - y0;
  for (int c = 0; c < 4; ++c) {
    auto at = [&](int px, int py) { return double(image.rgba[4 * (size_t(py) * image.width + px) + c]); };
    out[c] = float((1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
                   fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1)));
  }
  return true;
}

// PSNR of `image` against `pinhole` resampled at where each of image's pixels' centre ray lands in the
// pinhole, over the pixels where `ray_of` gives a ray inside the pinhole's image.
template <typename RayOf>
double resampled_psnr(const RenderImage& image, const RenderImage& pinhole, const Camera& pinhole_camera,
                      RayOf ray_of, int* compared) {
  double squared = 0;
  int count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      std::array<double, 3> ray{};
      if (!ray_of(x + 0.5, y + 0.5, ray) || !(ray[2] > 0)) continue;
      const double u = pinhole_camera.fx * ray[0] / ray[2] + pinhole_camera.cx;
      const double v = pinhole_camera.fy * ray[1] / ray[2] + pinhole_camera.cy;
      float expected[4];
      if (!sample_rgba(pinhole, u, v, expected)) continue;
      for (int c = 0; c < 4; ++c) {
        const double d = double(image.rgba[4 * (size_t(y) * image.width + x) + c]) - expected[c];
        squared += d * d;
      }
      ++count;
    }
  *compared = count;
  return 10 * std::log10(1.0 / (squared / (4.0 * std::max(count, 1))));
}

class CameraModels : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = load_scene(tilesplat::testing::bundled_playbot());
    pinhole_ = orbit_camera(scene_, 160, 120, {.azimuth_deg = 30, .vertical_fov_deg = 60});
    renderer_ = &tilesplat::testing::validated_renderer();
    renderer_->set_scene(scene_);
  }
  GaussianScene scene_;
  Camera pinhole_;
  Renderer* renderer_ = nullptr;
};

}  // namespace

TEST_F(CameraModels, EachMatchesTheFloat64Reference) {
  Camera inside = pinhole_;  // a panorama from the scene's centre, 2:1
  inside.width = 256;
  inside.height = 128;
  const Bounds bounds = compute_bounds(scene_);
  inside.position = {bounds.center[0], bounds.center[1] - 0.3, bounds.center[2]};
  const Camera cameras[] = {opencv_camera(pinhole_), fisheye_camera(pinhole_, 190),
                            orthographic_camera(pinhole_, 3.0), equirectangular_camera(inside)};
  for (const Camera& camera : cameras) {
    const RenderImage gpu = renderer_->render(camera);
    const RenderImage reference = render_reference(scene_, camera);
    const ImageDifference d = compare_images(gpu, reference);
    std::printf("[ measure  ] %s camera against the float64 reference: PSNR %.1f dB, max abs %.2e\n",
                camera_model_name(camera.model), d.psnr_db, d.max_abs);
    tilesplat::testing::expect_matches_reference(gpu, reference, 2e-3, camera_model_name(camera.model));
    double alpha = 0;
    for (size_t p = 0; p < gpu.pixels(); ++p) alpha += gpu.rgba[4 * p + 3];
    EXPECT_GT(alpha / double(gpu.pixels()), 0.02)
        << camera_model_name(camera.model) << ": the scene is in view";
  }
  EXPECT_EQ(renderer_->validation_messages(), 0u);
}

// Where a model and the pinhole see the same rays, the model's image is the pinhole's resampled: the
// fisheye's centre and the OpenCV camera's whole frame, through the model's own inverse (pixel_ray,
// solved here by Newton's method and bisection independently of the engine).
namespace {

// The ray of a fisheye pixel: theta_d = radius, solved for theta by bisection.
bool fisheye_ray(const Camera& camera, double u, double v, std::array<double, 3>& ray) {
  const double xd = (u - camera.cx) / camera.fx, yd = (v - camera.cy) / camera.fy;
  const double radius = std::hypot(xd, yd);
  const auto& k = camera.distortion;
  auto theta_d = [&](double t) {
    const double t2 = t * t;
    return t * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
  };
  double lo = 0, hi = std::numbers::pi / 2;
  if (!(radius < theta_d(hi))) return false;
  for (int i = 0; i < 100; ++i) (theta_d(0.5 * (lo + hi)) < radius ? lo : hi) = 0.5 * (lo + hi);
  const double theta = 0.5 * (lo + hi);
  const double across = radius > 0 ? std::sin(theta) / radius : 0;
  ray = {xd * across, yd * across, std::cos(theta)};
  return true;
}

// The ray of an OpenCV pixel: OpenCV's fixed-point undistortion (cv::undistortPoints' iteration).
bool opencv_ray(const Camera& camera, double u, double v, std::array<double, 3>& ray) {
  const auto& k = camera.distortion;
  const double xd = (u - camera.cx) / camera.fx, yd = (v - camera.cy) / camera.fy;
  double x = xd, y = yd;
  for (int i = 0; i < 200; ++i) {
    const double r2 = x * x + y * y;
    const double radial =
        (1 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]))) / (1 + r2 * (k[5] + r2 * (k[6] + r2 * k[7])));
    const double dx = 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x);
    const double dy = k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y;
    x = (xd - dx) / radial;
    y = (yd - dy) / radial;
  }
  ray = {x, y, 1};
  return std::isfinite(x) && std::isfinite(y);
}

}  // namespace

TEST(CameraModelResampling, AFisheyeCentreIsThePinholeImageResampled) {
  const GaussianScene blobs = separated_blobs(600, 0.08);
  Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(blobs);
  Camera fisheye = fisheye_camera(tilesplat::testing::axis_camera(200, 200, 100), 160);
  fisheye.distortion = {0.08, -0.01, 0.002, 0, 0, 0, 0, 0};
  // A pinhole of twice the fisheye's focal length, over +-64 degrees: sharper than the fisheye everywhere.
  Camera pinhole = tilesplat::testing::axis_camera(960, 960, 2 * fisheye.fx);
  const RenderImage wide = renderer.render(fisheye);
  const RenderImage narrow = renderer.render(pinhole);
  auto within = [](double limit_deg, auto ray_of) {
    return [=](double u, double v, std::array<double, 3>& ray) {
      return ray_of(u, v, ray) &&
             ray[2] > std::cos(limit_deg * std::numbers::pi / 180) * std::hypot(ray[0], ray[1], ray[2]);
    };
  };
  int compared = 0;
  const double psnr = resampled_psnr(
      wide, narrow, pinhole,
      within(55,
             [&](double u, double v, std::array<double, 3>& ray) { return fisheye_ray(fisheye, u, v, ray); }),
      &compared);
  std::printf(
      "[ measure  ] fisheye (160 deg) within 55 deg of its axis against the pinhole resampled, %d pixels: "
      "PSNR %.1f dB\n",
      compared, psnr);
  EXPECT_GT(compared, 12000);
  EXPECT_GE(psnr, 35.0);
  // The same check fails when the fisheye's angle mapping is wrong: an equidistant reading of a
  // distorted lens lands every ring at the wrong angle.
  Camera wrong = fisheye;
  wrong.distortion = {};
  const double wrong_psnr = resampled_psnr(
      wide, narrow, pinhole,
      within(55,
             [&](double u, double v, std::array<double, 3>& ray) { return fisheye_ray(wrong, u, v, ray); }),
      &compared);
  std::printf("[ measure  ] the same read as an equidistant fisheye: PSNR %.1f dB\n", wrong_psnr);
  EXPECT_LT(wrong_psnr, psnr - 6.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(CameraModelResampling, AnOpenCVFrameIsThePinholeImageResampled) {
  const GaussianScene shell = smooth_shell();
  Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(shell);
  const Camera distorted = opencv_camera(tilesplat::testing::axis_camera(160, 120, 100));
  // The pinhole of the same focal length over a wider field than the distorted frame's.
  const Camera pinhole = tilesplat::testing::axis_camera(320, 240, 100);
  const RenderImage image = renderer.render(distorted);
  const RenderImage reference = renderer.render(pinhole);
  int compared = 0;
  const double psnr = resampled_psnr(
      image, reference, pinhole,
      [&](double u, double v, std::array<double, 3>& ray) { return opencv_ray(distorted, u, v, ray); },
      &compared);
  std::printf("[ measure  ] OpenCV camera against the pinhole resampled, %d pixels: PSNR %.1f dB\n", compared,
              psnr);
  EXPECT_EQ(compared, distorted.width * distorted.height);
  EXPECT_GE(psnr, 35.0);
  const double undistorted_psnr = resampled_psnr(
      image, reference, pinhole,
      [&](double u, double v, std::array<double, 3>& ray) {
        return opencv_ray(tilesplat::testing::axis_camera(160, 120, 100), u, v, ray);  // the pinhole's rays
      },
      &compared);
  std::printf("[ measure  ] the same read as a pinhole: PSNR %.1f dB\n", undistorted_psnr);
  EXPECT_LT(undistorted_psnr, psnr - 6.0);
  // Zero coefficients are the pinhole itself, drawn by the pinhole's code: its frame to the bit.
  const Camera plain = tilesplat::testing::axis_camera(160, 120, 100);
  Camera zero = plain;
  zero.model = CameraModel::kOpenCV;
  const RenderImage zero_image = renderer.render(zero), plain_image = renderer.render(plain);
  EXPECT_EQ(zero_image.rgba, plain_image.rgba);
  EXPECT_EQ(zero_image.depth, plain_image.depth);
  EXPECT_EQ(zero_image.splat_count, plain_image.splat_count);
  EXPECT_EQ(render_reference(shell, zero).rgba, render_reference(shell, plain).rgba);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST_F(CameraModels, OrthographicIsTheLimitOfAFarTelephoto) {
  const Camera orthographic = orthographic_camera(pinhole_, 3.0);
  // A pinhole 1,000 times further back along its axis, zoomed so that the plane through the scene's
  // centre keeps its scale: its rays are parallel to within a milliradian over the scene.
  const Bounds bounds = compute_bounds(scene_);
  const double centre_depth =
      orthographic.to_camera({bounds.center[0], bounds.center[1], bounds.center[2]})[2];
  Camera telephoto = orthographic;
  telephoto.model = CameraModel::kPinhole;
  const double back = 1000 * centre_depth;
  for (int k = 0; k < 3; ++k) telephoto.position[size_t(k)] -= back * orthographic.rotation[size_t(6 + k)];
  telephoto.fx = orthographic.fx * (centre_depth + back);
  telephoto.fy = orthographic.fy * (centre_depth + back);
  RenderSettings settings;
  settings.depth = false;
  const ImageDifference d =
      compare_images(renderer_->render(orthographic, settings), renderer_->render(telephoto, settings));
  std::printf("[ measure  ] orthographic against a pinhole 1000x further back: PSNR %.1f dB\n", d.psnr_db);
  EXPECT_GE(d.psnr_db, 40.0);
  // A fisheye past 180 degrees sees what is behind it: the scene, from inside, in every direction.
  Camera inside = fisheye_camera(pinhole_, 360);
  inside.position = {bounds.center[0], bounds.center[1], bounds.center[2]};
  const RenderImage all_around = renderer_->render(inside);
  const RenderImage reference = render_reference(scene_, inside);
  tilesplat::testing::expect_matches_reference(all_around, reference, 2e-3, "fisheye 360 from inside");
  EXPECT_EQ(renderer_->validation_messages(), 0u);
}

TEST(CameraModelResampling, AnEquirectangularCentreIsThePinholeImageResampled) {
  const GaussianScene blobs = separated_blobs(600, 0.08);
  Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(blobs);
  const Camera panorama = equirectangular_camera(tilesplat::testing::axis_camera(512, 256, 100));
  const Camera pinhole = tilesplat::testing::axis_camera(600, 600, 2 * panorama.fx);  // +-57 degrees
  const RenderImage wide = renderer.render(panorama);
  const RenderImage narrow = renderer.render(pinhole);
  int compared = 0;
  auto within_45 = [](const Camera& camera) {
    return [camera](double u, double v, std::array<double, 3>& ray) {
      const double longitude = (u - camera.cx) / camera.fx, latitude = (v - camera.cy) / camera.fy;
      if (std::abs(longitude) > std::numbers::pi / 4 || std::abs(latitude) > std::numbers::pi / 4)
        return false;
      ray = {std::cos(latitude) * std::sin(longitude), std::sin(latitude),
             std::cos(latitude) * std::cos(longitude)};
      return true;
    };
  };
  const double psnr = resampled_psnr(wide, narrow, pinhole, within_45(panorama), &compared);
  std::printf(
      "[ measure  ] equirectangular within 45 deg of its axis against the pinhole resampled, %d pixels: "
      "PSNR %.1f dB\n",
      compared, psnr);
  EXPECT_GT(compared, 8000);
  EXPECT_GE(psnr, 35.0);
  Camera wrong = panorama;  // a panorama read with the latitude's scale off by 5%
  wrong.fy *= 1.05;
  const double wrong_psnr = resampled_psnr(wide, narrow, pinhole, within_45(wrong), &compared);
  std::printf("[ measure  ] the same read with a latitude scale 5%% off: PSNR %.1f dB\n", wrong_psnr);
  EXPECT_LT(wrong_psnr, psnr - 6.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The check on a real scene: each model rendered at twice the pinhole's scale, resampled through its
// own mapping (Camera::project) into the pinhole's pixels away from the borders, against the pinhole's
// render. What remains is the resampling's blur, the first-order footprint, and the order of overlapping
// splats (the fisheye and the panorama sort by distance, the pinhole by z).
TEST_F(CameraModels, OnTheBundledPlaybotEachModelResamplesToThePinhole) {
  // The pinhole supersampled 2x2: each pixel the mean of its four quarter-pixel samples' pixels.
  const Camera pinhole = orbit_camera(scene_, 160, 120, {.azimuth_deg = 30, .vertical_fov_deg = 50});
  const Camera fine = resize_camera(pinhole, 320, 240);
  const RenderImage fine_image = renderer_->render(fine);
  const double scale = 2 * pinhole.fy;  // the models' pixels per radian at their centre: the fine pinhole's
  struct Case {
    std::string name;
    Camera camera;
  };
  std::vector<Case> cases;
  for (const double fov : {120.0, 180.0, 240.0}) {
    Camera square = pinhole;
    square.width = square.height = int(std::ceil(scale * fov * std::numbers::pi / 180));
    square.cx = square.cy = square.width / 2.0;
    cases.push_back({"fisheye " + std::to_string(int(fov)), fisheye_camera(square, fov)});
  }
  Camera wide = pinhole;  // OpenCV at the fine pinhole's scale over 1.4 times its field
  wide.width = int(2.8 * pinhole.width);
  wide.height = int(2.8 * pinhole.height);
  wide.fx = wide.fy = scale;
  wide.cx = wide.width / 2.0;
  wide.cy = wide.height / 2.0;
  cases.push_back({"opencv", opencv_camera(wide)});
  Camera panorama = pinhole;
  panorama.width = int(std::ceil(2 * std::numbers::pi * scale));
  panorama.height = panorama.width / 2;
  cases.push_back({"equirectangular", equirectangular_camera(panorama)});

  for (const Case& c : cases) {
    const RenderImage image = renderer_->render(c.camera);
    double squared = 0;
    int compared = 0;
    for (int y = 8; y < pinhole.height - 8; ++y)
      for (int x = 8; x < pinhole.width - 8; ++x) {
        double model[4] = {0, 0, 0, 0}, expected[4] = {0, 0, 0, 0};
        bool inside = true;
        for (int sub = 0; sub < 4 && inside; ++sub) {
          const double u = x + 0.25 + 0.5 * (sub % 2), v = y + 0.25 + 0.5 * (sub / 2);
          const auto ray = pinhole.ray_direction(u, v);
          const auto at = c.camera.project({pinhole.position[0] + (*ray)[0], pinhole.position[1] + (*ray)[1],
                                            pinhole.position[2] + (*ray)[2]});
          float sampled[4];
          inside = at && sample_rgba(image, (*at)[0], (*at)[1], sampled);
          const size_t fine_pixel = size_t(2 * y + sub / 2) * size_t(fine.width) + size_t(2 * x + sub % 2);
          for (int ch = 0; ch < 4 && inside; ++ch) {
            model[ch] += 0.25 * sampled[ch];
            expected[ch] += 0.25 * fine_image.rgba[4 * fine_pixel + size_t(ch)];
          }
        }
        if (!inside) continue;
        for (int ch = 0; ch < 4; ++ch) squared += (model[ch] - expected[ch]) * (model[ch] - expected[ch]);
        ++compared;
      }
    const double psnr = 10 * std::log10(1.0 / (squared / (4.0 * std::max(compared, 1))));
    std::printf("[ measure  ] playbot, %s (%dx%d) resampled into the pinhole's %d pixels: PSNR %.1f dB\n",
                c.name.c_str(), c.camera.width, c.camera.height, compared, psnr);
    EXPECT_EQ(compared, (pinhole.width - 16) * (pinhole.height - 16)) << c.name;
    EXPECT_GE(psnr, 30.0) << c.name;
  }
  EXPECT_EQ(renderer_->validation_messages(), 0u);
}

TEST(CameraModelSeam, ASplatBehindAPanoramaShowsOnBothEdges) {
  GaussianScene scene;
  scene.positions = {0.3f, 0, -5};  // a little off straight behind: its centre just inside the right edge
  scene.log_scales = {std::log(0.4f), std::log(0.4f), std::log(0.4f)};
  scene.rotations = {1, 0, 0, 0};
  scene.opacity_logits = {4};
  scene.sh = {1, 1, 1};
  const Camera panorama = equirectangular_camera(tilesplat::testing::axis_camera(256, 128, 100));
  Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(scene);
  const RenderImage image = renderer.render(panorama);
  const size_t row = 64;
  const float left = image.rgba[4 * (row * 256 + 0) + 3], right = image.rgba[4 * (row * 256 + 255) + 3];
  EXPECT_GT(left, 0.3f);  // the splat is cut by neither edge: both hold it
  EXPECT_GT(right, 0.3f);
  // Across the seam the image is what the panorama turned half a turn shows in its middle: column
  // 128 + k there is column k here (mod 256).
  Camera turned = panorama;
  turned.rotation = {-1, 0, 0, 0, 1, 0, 0, 0, -1};
  const RenderImage middle = renderer.render(turned);
  for (int k = -12; k < 12; ++k) {
    const size_t here = row * 256 + size_t((k + 256) % 256), there = row * 256 + size_t(128 + k);
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(image.rgba[4 * here + c], middle.rgba[4 * there + c], 1e-4) << "column offset " << k;
  }
  tilesplat::testing::expect_matches_reference(image, render_reference(scene, panorama), 2e-3, "seam");
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(CameraModelChecks, ProjectAndRayDirectionAreInverses) {
  Camera base = look_at_camera({0.3, -1.2, -4.0}, {0.1, 0.2, 0.3}, {0, -1, 0}, 640, 480, 60.0);
  Camera opencv = base;
  opencv.model = CameraModel::kOpenCV;
  opencv.distortion = {-0.2, 0.05, 0.001, -0.002, 0, 0, 0, 0};
  for (const Camera& camera : {base, opencv, fisheye_camera(base, 250), equirectangular_camera(base)}) {
    for (const auto& [u, v] : {std::pair{320.0, 240.0}, {100.5, 120.25}, {600.0, 400.0}}) {
      const auto ray = camera.ray_direction(u, v);
      ASSERT_TRUE(ray.has_value()) << camera_model_name(camera.model);
      const std::array<double, 3> point = {camera.position[0] + 3 * (*ray)[0],
                                           camera.position[1] + 3 * (*ray)[1],
                                           camera.position[2] + 3 * (*ray)[2]};
      const auto pixel = camera.project(point);
      ASSERT_TRUE(pixel.has_value()) << camera_model_name(camera.model);
      EXPECT_NEAR((*pixel)[0], u, 1e-6) << camera_model_name(camera.model);
      EXPECT_NEAR((*pixel)[1], v, 1e-6) << camera_model_name(camera.model);
    }
  }
  EXPECT_FALSE(base.project({0.3, -1.2, -10.0}).has_value());              // behind the pinhole
  EXPECT_FALSE(fisheye_camera(base, 250).ray_direction(0, 0).has_value());  // 208 degrees off the axis
  const Camera orthographic = orthographic_camera(base, 2.0);
  const auto axis = orthographic.ray_direction(0, 0);
  ASSERT_TRUE(axis.has_value());
  for (size_t k = 0; k < 3; ++k) EXPECT_NEAR((*axis)[k], base.rotation[6 + k], 1e-15);
}

TEST(CameraModelChecks, BadCoefficientsAndUnsupportedCombinationsAreClearErrors) {
  Camera camera = tilesplat::testing::axis_camera(64, 48, 50);
  camera.distortion[0] = 0.1;
  EXPECT_NE(tilesplat::testing::error_of([&] {
              validate(camera);
            }).find("the pinhole camera has 0 distortion coefficients, but coefficient 0 is"),
            std::string::npos);
  camera.model = CameraModel::kFisheye;
  camera.distortion[5] = 0.1;
  EXPECT_NE(tilesplat::testing::error_of([&] { validate(camera); }).find("coefficient 5"), std::string::npos);
  camera.distortion = {};
  camera.distortion[2] = std::nan("");
  EXPECT_NE(
      tilesplat::testing::error_of([&] { validate(camera); }).find("non-finite distortion coefficient 2"),
      std::string::npos);
  camera.distortion = {};
  camera.model = static_cast<CameraModel>(7);
  EXPECT_NE(tilesplat::testing::error_of([&] { validate(camera); }).find("unknown camera model 7"),
            std::string::npos);
  EXPECT_THROW(parse_camera_model("equirect"), std::invalid_argument);
  EXPECT_EQ(parse_camera_model("fisheye"), CameraModel::kFisheye);
  EXPECT_THROW(fisheye_camera(camera, 0), std::invalid_argument);
  EXPECT_THROW(fisheye_camera(camera, 361), std::invalid_argument);
  EXPECT_THROW(orthographic_camera(camera, -1), std::invalid_argument);

  // The per-pixel re-sorting and the thin lens are the pinhole's.
  const GaussianScene scene = load_scene(tilesplat::testing::bundled_sh3());
  const Camera fisheye = fisheye_camera(tilesplat::testing::axis_camera(64, 48, 50), 180);
  RenderSettings resort;
  resort.accuracy.resort_window = 4;
  EXPECT_NE(tilesplat::testing::error_of([&] {
              render_reference(scene, fisheye, resort);
            }).find("per-pixel re-sorting (resort4) needs a pinhole camera, not fisheye"),
            std::string::npos);
  Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(scene);
  EXPECT_NE(tilesplat::testing::error_of([&] {
              renderer.render(fisheye, resort);
            }).find("needs a pinhole camera, not fisheye"),
            std::string::npos);
  RenderSettings lens;
  lens.lens = {.aperture_diameter = 0.1, .focus_distance = 2, .samples = 4};
  EXPECT_NE(tilesplat::testing::error_of([&] {
              renderer.render(fisheye, lens);
            }).find("depth of field needs a pinhole camera, not fisheye"),
            std::string::npos);
}
