// Prints a hash of every output of a frame (colour, depth, splat count) over a matrix of settings:
// every accuracy mode x every exact sort strategy, and every effect row of the effects table (SH
// degrees, relighting, antialiasing, outputs off, background, stochastic compositor) x every exact
// strategy. Uses the public API only, so the same source builds against an older checkout:
// tests/bench/frame_hashes_ab.sh compares two commits' tables line by line (a refactor must change no
// pixel).
//
//   tilesplat_frame_hashes SCENE.ply CAMERAS.json [WIDTH HEIGHT]
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/camera_sets.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace {

// FNV-1a, 64-bit: enough to tell two frames apart, and written out so the tool needs no library.
uint64_t fnv1a(uint64_t hash, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * 0x100000001b3ull;
  return hash;
}

uint64_t hash_image(const tilesplat::RenderImage& image) {
  uint64_t h = 0xcbf29ce484222325ull;
  h = fnv1a(h, image.rgba.data(), image.rgba.size() * sizeof(float));
  h = fnv1a(h, image.depth.data(), image.depth.size() * sizeof(float));
  h = fnv1a(h, image.splat_count.data(), image.splat_count.size() * sizeof(image.splat_count[0]));
  h = fnv1a(h, image.host_depth.data(), image.host_depth.size() * sizeof(float));
  return h;
}

struct Row {
  std::string name;
  tilesplat::RenderSettings settings;
};

// A host's depth, in a Vulkan projection's convention (near 0.1, far 100): a surface 3 units away over
// the left half of the image, the cleared far value on the right.
tilesplat::DepthConvention host_convention() {
  tilesplat::DepthConvention convention;
  convention.a = 100.0 / 99.9;
  convention.b = -10.0 / 99.9;
  return convention;
}
std::vector<float> host_surface(const tilesplat::Camera& camera) {
  const tilesplat::DepthConvention convention = host_convention();
  std::vector<float> depth(size_t(camera.width) * size_t(camera.height), float(convention.far_depth()));
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width / 2; ++x)
      depth[size_t(y) * size_t(camera.width) + size_t(x)] = float(convention.window_depth(3.0));
  return depth;
}

std::vector<Row> rows(const std::vector<float>& host_depth) {
  using namespace tilesplat;
  std::vector<Row> out;
  for (const char* modes : {"reference", "depth24", "depth16", "opacity-extent", "square-tiles", "sh0", "sh1",
                            "sh2", "fp16-sh", "fp16-cov", "t-cutoff=0.001", "alpha-cutoff=1/64", "resort4",
                            "resort16", "depth16+sh1+fp16-cov+opacity-extent"}) {
    RenderSettings s;
    s.accuracy = parse_accuracy_modes(modes);
    out.push_back({std::string("mode ") + modes, s});
  }
  RenderSettings s;
  s.antialiasing = Antialiasing::kAntialiased;
  out.push_back({"effect antialiased", s});
  s = {};
  s.antialiasing = Antialiasing::kMip;
  out.push_back({"effect mip", s});
  s = {};
  s.lighting.lights.push_back(
      {Light::Type::kDirectional, {0.3f, -1.0f, 0.2f}, {0, 0, 0}, {1, 0.9f, 0.8f}, 2.0f});
  s.lighting.ambient = {0.2f, 0.2f, 0.2f};
  out.push_back({"effect relighting", s});
  s = {};
  s.depth = false;
  s.splat_count = false;
  out.push_back({"effect colour-only", s});
  s = {};
  s.background = {0.25f, 0.5f, 1.0f};
  out.push_back({"effect background", s});
  s = {};
  s.compositor = Compositor::kStochastic;
  s.stochastic.frames = 4;
  out.push_back({"effect stochastic", s});
  s = {};
  s.host = HostDepth{};
  s.host->convention = host_convention();
  s.host->depth = host_depth;
  s.host->write_depth = true;
  out.push_back({"effect host-depth", s});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 && argc != 5) {
    std::fprintf(stderr, "usage: tilesplat_frame_hashes SCENE CAMERAS.json [WIDTH HEIGHT]\n");
    return 2;
  }
  try {
    using namespace tilesplat;
    const GaussianScene scene = load_scene(argv[1]);
    Camera camera = load_camera_set(argv[2]).at(0).camera;
    if (argc == 5) camera = resize_camera(camera, std::stoi(argv[3]), std::stoi(argv[4]));
    auto renderer = Renderer::create();
    renderer->set_scene(scene);
    const std::vector<float> host_depth = host_surface(camera);
    for (const Row& row : rows(host_depth)) {
      for (const std::string& sort : sort_strategies()) {
        if (!sort_strategy_is_exact(sort)) continue;
        RenderSettings settings = row.settings;
        settings.sort = sort;
        settings.reuse_lists = false;
        const RenderImage image = renderer->render(camera, settings);
        std::printf("%-44s %-12s %016llx\n", row.name.c_str(), sort.c_str(),
                    static_cast<unsigned long long>(hash_image(image)));
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tilesplat_frame_hashes: %s\n", e.what());
    return 1;
  }
  return 0;
}
