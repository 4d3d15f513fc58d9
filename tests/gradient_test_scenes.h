// What the gradient tests (test_reference_backward.cpp, test_gradients.cpp) render and differentiate: a
// camera, random splats a few pixels wide in front of it, and random gradients of a frame's outputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>

#include "tilesplat/camera.h"
#include "tilesplat/gradients.h"
#include "tilesplat/scene.h"

namespace tilesplat::testing {

inline Camera gradient_camera(int width, int height) {
  return look_at_camera({0.3, -0.2, -4.0}, {0.0, 0.1, 0.0}, {0, -1, 0}, width, height, 50.0);
}

// `n` splats in front of gradient_camera, with SH to degree 3 and opacities from faint to past the alpha
// cap; log scales within 0.5 of `log_scale`.
inline GaussianScene random_splats(size_t n, uint32_t seed, float log_scale = -2.2f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  GaussianScene scene;
  scene.sh_degree = 3;
  for (size_t i = 0; i < n; ++i) {
    scene.positions.insert(scene.positions.end(), {0.9f * unit(rng), 0.7f * unit(rng), 0.8f * unit(rng)});
    scene.log_scales.insert(
        scene.log_scales.end(),
        {log_scale + 0.5f * unit(rng), log_scale + 0.5f * unit(rng), log_scale + 0.5f * unit(rng)});
    scene.rotations.insert(scene.rotations.end(), {unit(rng), unit(rng), unit(rng), unit(rng)});
    scene.opacity_logits.push_back(1.5f + 2.5f * unit(rng));
    for (int k = 0; k < 16; ++k)
      for (int c = 0; c < 3; ++c) scene.sh.push_back(k == 0 ? 0.8f * unit(rng) : 0.25f * unit(rng));
  }
  return scene;
}

// dL/d(every output) of a width x height frame, uniform in [-1, 1] (depths' in [-0.1, 0.1]).
inline FrameGradients random_frame_gradients(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const size_t pixels = size_t(width) * size_t(height);
  FrameGradients g;
  for (size_t k = 0; k < 3 * pixels; ++k) g.rgb.push_back(unit(rng));
  for (size_t k = 0; k < pixels; ++k) {
    g.alpha.push_back(unit(rng));
    g.expected_depth.push_back(0.1f * unit(rng));
    g.accumulated_depth.push_back(0.1f * unit(rng));
  }
  return g;
}

}  // namespace tilesplat::testing
