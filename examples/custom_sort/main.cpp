// Registers the serial-radix strategy in this program and holds it to tilesplat's contract: the
// same order as the built-in radix sort on random 32- and 64-bit keys (ties included), and the
// same image, bit for bit, on a real scene.
//
//   custom_sort SCENE [WIDTH HEIGHT]
#include <tilesplat/camera.h>
#include <tilesplat/image.h>
#include <tilesplat/renderer.h>
#include <tilesplat/scene.h>
#include <tilesplat/sort_strategy.h>

#include <cstdio>
#include <exception>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "serial_radix_sort.h"

namespace {

bool same_order(tilesplat::Renderer& renderer, uint32_t key_bits, size_t count) {
  std::mt19937_64 random(key_bits);
  std::vector<uint64_t> keys(count);
  // Few distinct values in the low bits make many ties, which only a stable sort orders right.
  for (auto& key : keys) key = (random() >> (64 - key_bits)) & ~uint64_t{0xF0};
  const auto built_in = renderer.sort_keys("radix", keys, key_bits);
  const auto custom = renderer.sort_keys(SerialRadixSort::kName, keys, key_bits);
  const bool same = custom.order == built_in.order && custom.keys == built_in.keys;
  std::printf("%zu random %u-bit keys: %s (radix %.2f ms, serial-radix %.2f ms)\n", count, key_bits,
              same ? "same order" : "DIFFERENT ORDER", built_in.gpu_ms, custom.gpu_ms);
  return same;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && argc != 4) {
    std::fprintf(stderr, "usage: custom_sort SCENE [WIDTH HEIGHT]\n");
    return 2;
  }
  try {
    tilesplat::register_sort_strategy(SerialRadixSort::kName, [](const tilesplat::SortDevice& device) {
      return std::make_unique<SerialRadixSort>(device);
    });
    const int width = argc == 4 ? std::stoi(argv[2]) : 480;
    const int height = argc == 4 ? std::stoi(argv[3]) : 270;

    auto renderer = tilesplat::Renderer::create();
    bool ok = same_order(*renderer, 32, 100000) && same_order(*renderer, 64, 100000);

    const tilesplat::GaussianScene scene = tilesplat::load_scene(argv[1]);
    renderer->set_scene(scene);
    const tilesplat::Camera camera = tilesplat::orbit_camera(scene, width, height);
    tilesplat::RenderSettings settings;
    settings.reuse_lists = false;  // two whole frames, each sorting with its own strategy
    settings.sort = "radix";
    const tilesplat::RenderImage built_in = renderer->render(camera, settings);
    const double built_in_ms = renderer->last_frame_stats().gpu_ms;
    settings.sort = SerialRadixSort::kName;
    const tilesplat::RenderImage custom = renderer->render(camera, settings);
    const double custom_ms = renderer->last_frame_stats().gpu_ms;
    const bool same_image = custom.rgba == built_in.rgba && custom.depth == built_in.depth &&
                            custom.splat_count == built_in.splat_count;
    std::printf("%s at %dx%d: %s (GPU frame: radix %.1f ms, serial-radix %.1f ms)\n", argv[1], width, height,
                same_image ? "bit-identical images" : "DIFFERENT IMAGES", built_in_ms, custom_ms);
    ok = ok && same_image;
    return ok ? 0 : 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "custom_sort: %s\n", error.what());
    return 1;
  }
}
