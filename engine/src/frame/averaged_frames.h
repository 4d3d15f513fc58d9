// Frames averaged from samples: through a thin lens (RenderSettings::lens), the mean in linear light of
// the pinhole frames of its lens samples; through an open shutter over camera motion
// (RenderSettings::shutter), of the frames at its times. The GPU renderer and the float64 reference both
// make them this way, each rendering the sample frames its own way, so that they are held to one definition.
#pragma once

#include <functional>
#include <string>

#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene_description.h"
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

// Whether `settings` ask for a frame averaged from sample frames: an enabled shutter or lens.
bool averages_samples(const RenderSettings& settings);

// RenderSettings::accumulate_samples with an enabled lens or shutter where sums cannot be kept from call
// to call (`where`: a scene given to render() each call, the float64 reference): std::invalid_argument.
void refuse_accumulated_samples(const RenderSettings& settings, const std::string& where);

// Renders one sample frame: a camera and the settings without the effect being averaged.
using SampleRenderer = std::function<RenderImage(const Camera&, const RenderSettings&)>;
// The same, told the sample's time in the frame (a shutter's time; 0 for the lens samples of a frame
// without one): for scenes whose models move (SceneInstances::moves).
using TimedSampleRenderer = std::function<RenderImage(const Camera&, const RenderSettings&, double time)>;

// The averaged frame of `camera` (averages_samples(settings)), checked first (check_shutter, check_lens).
// With an enabled shutter: the linear mean (LinearFrameMean, over settings.background) of
// render_sample(camera_between(camera, end_camera, t), settings without the shutter) over shutter_times(...);
// those settings may still hold a lens, which render_sample averages in turn. Otherwise, through the lens:
// the mean of render_sample(lens_sample_camera(camera, lens, s), settings without the lens) over
// lens_samples(lens.samples). A rolling shutter (ShutterScan other than kGlobal) stitches instead of
// averaging: band k of its bands, in the scan's order, from render_sample(camera_between(...,
// shutter_times(open, close, bands)[k]), settings without the shutter). Samples are rendered in that order.
RenderImage render_averaged(const Camera& camera, const RenderSettings& settings,
                            const SampleRenderer& render_sample);
RenderImage render_averaged(const Camera& camera, const RenderSettings& settings,
                            const TimedSampleRenderer& render_sample);

// Whether a scene file's copies that move (SceneInstances::moves) blur in this frame: an open shutter
// (close > open), whether the camera moves or not.
bool blurs_moving_models(const SceneInstances& scene, const RenderSettings& settings);
// The settings such a frame averages under: the shutter's end camera the camera itself where it has none
// (a still camera), so that render_averaged takes the shutter's times.
RenderSettings shutter_over_moving_models(const RenderSettings& settings, const Camera& camera);

// Adds a sample frame's statistics to those of the frame it is part of (add_frame_stats: the largest
// visible and intersection counts, each sample being the whole frame); samples summed (a sample that was
// itself averaged brings its own count). frame.samples == 0: `sample` is the first, and becomes the frame's.
void add_sample_stats(FrameStats& frame, const FrameStats& sample);

}  // namespace tilesplat
