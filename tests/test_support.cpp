#include "test_support.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace tilesplat::testing {

std::filesystem::path bundled_scene_dir() { return std::filesystem::path(TILESPLAT_SOURCE_DIR) / "scenes"; }
std::filesystem::path bundled_playbot() {
  return bundled_scene_dir() / "playbot_lod3" / "playbot_lod3_31000_sh2.ply";
}
std::filesystem::path bundled_playbot_cameras() {
  return bundled_scene_dir() / "playbot_lod3" / "playbot_lod3_31000_sh2.json";
}
std::filesystem::path bundled_sh3() {
  return bundled_scene_dir() / "playcanvas_test" / "playcanvas_test_64_sh3.ply";
}
std::filesystem::path bundled_sh3_cameras() {
  return bundled_scene_dir() / "playcanvas_test" / "playcanvas_test_64_sh3.json";
}

std::filesystem::path shared_scenes() {
  std::filesystem::path dir;
  if (const char* env = std::getenv("TILESPLAT_SHARED_SCENES"); env && *env)
    dir = env;
  else
    dir = TILESPLAT_SHARED_SCENES_DEFAULT;
  std::error_code ec;
  if (std::filesystem::is_directory(dir / "cameras", ec)) return dir;
  return {};
}

bool skips_forbidden() {
  const char* value = std::getenv("TILESPLAT_NO_SKIPS");
  return value && *value && std::string(value) != "0";
}

Camera axis_camera(int width, int height, double focal) {
  Camera camera;
  camera.width = width;
  camera.height = height;
  camera.fx = camera.fy = focal;
  camera.cx = width / 2.0;
  camera.cy = height / 2.0;
  return camera;
}

std::filesystem::path temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "tilesplat";
  for (char& c : name)
    if (c == '/') c = '_';
  auto dir = std::filesystem::temp_directory_path() / "tilesplat_tests" / name;
  std::filesystem::create_directories(dir);
  return dir;
}

Renderer& validated_renderer() {
  static std::unique_ptr<Renderer> renderer = [] {
    RendererOptions options;
    options.validation = true;
    return Renderer::create(options);
  }();
  return *renderer;
}

void expect_composite_layouts_identical(const GaussianScene& scene, const Camera& camera,
                                        const RenderSettings& settings) {
  std::vector<RenderImage> images;
  struct Layout {
    const char* pixels;         // TILESPLAT_COMPOSITE_PIXELS
    const char* texel_buffers;  // TILESPLAT_TEXEL_BUFFERS
  };
  for (const Layout& layout : {Layout{"1", "0"}, Layout{"4", "1"}, Layout{"16", "0"}, Layout{"16", "1"}}) {
    ::setenv("TILESPLAT_COMPOSITE_PIXELS", layout.pixels, 1);
    ::setenv("TILESPLAT_TEXEL_BUFFERS", layout.texel_buffers, 1);
    RendererOptions options;
    options.validation = true;
    auto renderer = Renderer::create(options);
    ::unsetenv("TILESPLAT_COMPOSITE_PIXELS");
    ::unsetenv("TILESPLAT_TEXEL_BUFFERS");
    renderer->set_scene(scene);
    images.push_back(renderer->render(camera, settings));
    EXPECT_EQ(renderer->validation_messages(), 0u)
        << layout.pixels << " pixels per invocation, texel buffers " << layout.texel_buffers;
  }
  for (size_t k = 1; k < images.size(); ++k) {
    EXPECT_EQ(images[k].rgba, images[0].rgba) << "layout " << k;
    EXPECT_EQ(images[k].depth, images[0].depth) << "layout " << k;
    EXPECT_EQ(images[k].splat_count, images[0].splat_count) << "layout " << k;
  }
}

DecodedPng read_png_rgb(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) throw std::runtime_error(png.message);
  png.format = PNG_FORMAT_RGB;
  DecodedPng decoded;
  decoded.width = png.width;
  decoded.height = png.height;
  decoded.rgb.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, decoded.rgb.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw std::runtime_error(message);
  }
  return decoded;
}

}  // namespace tilesplat::testing
