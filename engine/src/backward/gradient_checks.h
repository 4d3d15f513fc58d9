// What every backward refuses before any work, in the same words: the frames it does not cover
// (check_differentiable, tilesplat/gradients.h) and gradients of the wrong size or not finite.
#pragma once

#include <string>

#include "tilesplat/gradients.h"

namespace tilesplat {

// Throws std::invalid_argument ("<caller>: FrameGradients::<channel> ...") unless each channel is empty or
// holds one finite value per pixel of a width x height image (three for rgb).
void check_frame_gradients(const FrameGradients& gradients, int width, int height, const std::string& caller);

}  // namespace tilesplat
