// The smallest program that renders with tilesplat: one view of a trainer's cameras.json, to EXR.
//
//   render_exr SCENE CAMERAS.json VIEW WIDTH HEIGHT OUT.exr
//
// SCENE is any format tilesplat reads (.ply, .spz, .sog, ...). The image is premultiplied RGBA over
// black, scene-linear (the sRGB decoding of the trained colours), as tilesplat-render writes it.
#include <tilesplat/camera.h>
#include <tilesplat/image.h>
#include <tilesplat/renderer.h>
#include <tilesplat/scene.h>
#include <tilesplat/version.h>

#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s SCENE CAMERAS.json VIEW WIDTH HEIGHT OUT.exr\n", argv[0]);
    return 2;
  }
  try {
    const tilesplat::GaussianScene scene = tilesplat::load_scene(argv[1]);
    const tilesplat::CameraView view = tilesplat::load_cameras_json(argv[2]).at(std::stoul(argv[3]));
    const tilesplat::Camera camera =
        tilesplat::resize_camera(view.camera, std::stoi(argv[4]), std::stoi(argv[5]));

    const auto renderer = tilesplat::Renderer::create();  // the first Vulkan device with what it needs
    renderer->set_scene(scene);                           // uploads once; render as many views as you like
    tilesplat::write_exr(argv[6], renderer->render(camera));

    std::printf("tilesplat %s: %zu Gaussians, view '%s' at %dx%d -> %s\n", tilesplat::version(), scene.size(),
                view.name.c_str(), camera.width, camera.height, argv[6]);
  } catch (const std::exception& error) {  // tilesplat::SceneError names the file and the problem
    std::fprintf(stderr, "render_exr: %s\n", error.what());
    return 1;
  }
  return 0;
}
