// Frames averaged from samples: through a thin lens (RenderSettings::lens), the mean in linear light of
// the pinhole frames of its lens samples; through an open shutter over camera motion
// (RenderSettings::shutter), of the frames at its times. The GPU renderer and the float64 reference both
// make them this way, each rendering the sample frames its own way, so that they are held to one definition.
#pragma once

#include <functional>

#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/renderer.h"
#include "tilesplat/shutter.h"

namespace tilesplat {

// The mean of frames as a sensor integrates light: colours averaged in linear light (each frame's display
// values decoded, A * decode(C / A), the mean encoded back), alpha averaged, depth the alpha-weighted mean of
// the frames' depths (0 where no frame blended a splat), splat counts the rounded mean. Frames blended over
// a background (RenderSettings::background not black) hold it in their colours, which are then not
// premultiplied by alpha: `over_background` converts each pixel as an opaque colour, decode(C).
class LinearFrameMean {
 public:
  explicit LinearFrameMean(bool over_background) : over_background_(over_background) {}
  void add(const RenderImage& frame);
  RenderImage mean() const;

 private:
  bool over_background_ = false;
  int frames_ = 0;
  int width_ = 0, height_ = 0;
  bool depth_ = false, count_ = false;
  std::vector<double> linear_rgba_;
  std::vector<double> alpha_depth_;  // sum of A * depth
  std::vector<double> counts_;
};

// The frame of `camera` through the lens of `settings` (enabled): the linear mean (LinearFrameMean, over
// settings.background) of render_pinhole(lens_sample_camera(...)) over lens_samples(lens.samples), in order.
RenderImage render_lens_frames(const Camera& camera, const RenderSettings& settings,
                               const std::function<RenderImage(const Camera&)>& render_pinhole);

// The frame of `camera` through the shutter of `settings` (enabled): the linear mean over
// settings.background of render_frame(camera_between(camera, end_camera, t)) over shutter_times(...), in
// order.
RenderImage render_shutter_frames(const Camera& camera, const RenderSettings& settings,
                                  const std::function<RenderImage(const Camera&)>& render_frame);

// Adds a sample frame's statistics to those of the frame it is part of: GPU times summed (pass by pass),
// the largest visible and intersection counts, retries and submissions summed; samples summed (a sample
// that was itself averaged brings its own count). frame.samples == 0: `sample` is the first, and becomes
// the frame's.
void add_sample_stats(FrameStats& frame, const FrameStats& sample);

}  // namespace tilesplat
