#include "frame/averaged_frames.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "frame/frame_stats_sum.h"
#include "frame/image_regions.h"
#include "settings_checks.h"

namespace tilesplat {

void LinearFrameMean::add(const RenderImage& frame) {
  if (frames_ == 0) {
    width_ = frame.width;
    height_ = frame.height;
    depth_ = !frame.depth.empty();
    count_ = !frame.splat_count.empty();
    linear_rgba_.assign(frame.rgba.size(), 0.0);
    alpha_depth_.assign(depth_ ? frame.depth.size() : 0, 0.0);
    counts_.assign(count_ ? frame.splat_count.size() : 0, 0.0);
  } else if (frame.width != width_ || frame.height != height_ || frame.rgba.size() != linear_rgba_.size() ||
             frame.depth.empty() == depth_ || frame.splat_count.empty() == count_) {
    throw std::logic_error("LinearFrameMean: the frames differ in size or outputs");
  }
  const std::vector<float> linear = convert_colours(frame.rgba, ColourEncoding::kSrgbDisplay,
                                                    ColourEncoding::kSceneLinear, over_background_);
  for (size_t i = 0; i < linear.size(); ++i) linear_rgba_[i] += linear[i];
  for (size_t p = 0; p < alpha_depth_.size(); ++p)
    alpha_depth_[p] += double(frame.rgba[4 * p + 3]) * frame.depth[p];
  for (size_t p = 0; p < counts_.size(); ++p) counts_[p] += frame.splat_count[p];
  ++frames_;
}

RenderImage LinearFrameMean::mean() const {
  if (frames_ == 0) throw std::logic_error("LinearFrameMean: no frames");
  RenderImage image;
  image.width = width_;
  image.height = height_;
  std::vector<float> linear(linear_rgba_.size());
  for (size_t i = 0; i < linear.size(); ++i) linear[i] = static_cast<float>(linear_rgba_[i] / frames_);
  image.rgba =
      convert_colours(linear, ColourEncoding::kSceneLinear, ColourEncoding::kSrgbDisplay, over_background_);
  if (depth_) {
    image.depth.resize(alpha_depth_.size());
    for (size_t p = 0; p < alpha_depth_.size(); ++p) {
      const double alpha_sum = linear_rgba_[4 * p + 3];
      image.depth[p] = alpha_sum > 0 ? static_cast<float>(alpha_depth_[p] / alpha_sum) : 0.0f;
    }
  }
  if (count_) {
    image.splat_count.resize(counts_.size());
    for (size_t p = 0; p < counts_.size(); ++p)
      image.splat_count[p] = static_cast<uint32_t>(std::lround(counts_[p] / frames_));
  }
  return image;
}

bool averages_samples(const RenderSettings& settings) {
  return settings.shutter.enabled() || settings.lens.enabled();
}

void refuse_accumulated_samples(const RenderSettings& settings, const std::string& where) {
  if (settings.accumulate_samples && averages_samples(settings))
    throw std::invalid_argument(
        "RenderSettings::accumulate_samples: " + where +
        " keeps no samples from call to call (Renderer::render(camera, settings) on the scene set_scene "
        "uploaded and render_to_image do): render the frame's samples in one call, without it");
}

namespace {

// A rolling shutter's frame: band k of the image (in the scan's order) rendered at the k-th of the
// shutter's times, each band a region of the camera's image (RenderSettings::region: its pixels are the
// whole frame's at that time, and it costs the projection and its own share of the rest). With a
// region of the caller's, each band's part of it.
RenderImage render_rolling(const Camera& camera, const RenderSettings& settings,
                           const TimedSampleRenderer& render_sample) {
  const Shutter& shutter = settings.shutter;
  const bool rows = shutter.scan == ShutterScan::kTopToBottom || shutter.scan == ShutterScan::kBottomToTop;
  const bool reversed =
      shutter.scan == ShutterScan::kBottomToTop || shutter.scan == ShutterScan::kRightToLeft;
  const int extent = rows ? camera.height : camera.width;
  const int bands = std::min(shutter.samples, extent);
  const PixelRegion wanted = resolved_region(settings.region, camera.width, camera.height);
  RenderSettings sample_settings = settings;
  sample_settings.shutter = {};
  RenderImage image = image_to_assemble(wanted, settings);
  const std::vector<double> times = shutter_times(shutter.open, shutter.close, bands);
  for (int k = 0; k < bands; ++k) {
    // Band k in scan order covers [first, last) along the scan's axis, counted from where the scan starts.
    const int first = int(int64_t(k) * extent / bands), last = int(int64_t(k + 1) * extent / bands);
    const int begin = reversed ? extent - last : first, end = reversed ? extent - first : last;
    const PixelRegion band = rows ? PixelRegion{0, begin, camera.width, end - begin}
                                  : PixelRegion{begin, 0, end - begin, camera.height};
    // The band's part of the wanted pixels, if any.
    const int x0 = std::max(band.x, wanted.x), x1 = std::min(band.x + band.width, wanted.x + wanted.width);
    const int y0 = std::max(band.y, wanted.y), y1 = std::min(band.y + band.height, wanted.y + wanted.height);
    if (x1 <= x0 || y1 <= y0) continue;
    sample_settings.region = {x0, y0, x1 - x0, y1 - y0};
    const RenderImage frame = render_sample(camera_between(camera, *shutter.end_camera, times[size_t(k)]),
                                            sample_settings, times[size_t(k)]);
    paste(image, wanted, frame, sample_settings.region);
  }
  return image;
}

}  // namespace

RenderImage render_averaged(const Camera& camera, const RenderSettings& settings,
                            const SampleRenderer& render_sample) {
  return render_averaged(
      camera, settings,
      TimedSampleRenderer([&](const Camera& sample_camera, const RenderSettings& sample_settings, double) {
        return render_sample(sample_camera, sample_settings);
      }));
}

RenderImage render_averaged(const Camera& camera, const RenderSettings& settings,
                            const TimedSampleRenderer& render_sample) {
  refuse_accumulated_samples(settings, "this renderer");
  validate(settings.region, camera.width, camera.height);
  LinearFrameMean mean(settings.background != std::array<float, 3>{0, 0, 0});
  RenderSettings sample_settings = settings;
  if (settings.shutter.enabled() && settings.shutter.scan != ShutterScan::kGlobal) {
    check_shutter(settings, camera);
    return render_rolling(camera, settings, render_sample);
  }
  if (settings.shutter.enabled()) {
    check_shutter(settings, camera);
    const Shutter& shutter = settings.shutter;
    sample_settings.shutter = {};
    for (int i = 0; i < shutter.samples; ++i) {
      const double t = shutter_time(shutter.open, shutter.close, shutter.pattern, i, shutter.samples);
      mean.add(render_sample(camera_between(camera, *shutter.end_camera, t), sample_settings, t));
    }
  } else {
    check_lens(settings, camera);
    const ThinLens& lens = settings.lens;
    sample_settings.lens = {};
    for (int i = 0; i < lens.samples; ++i)
      mean.add(render_sample(lens_sample_camera(camera, lens, lens_sample(lens.pattern, i, lens.samples)),
                             sample_settings, 0.0));
  }
  return mean.mean();
}

bool blurs_moving_models(const SceneInstances& scene, const RenderSettings& settings) {
  return scene.moves() && settings.shutter.opens();
}

RenderSettings shutter_over_moving_models(const RenderSettings& settings, const Camera& camera) {
  RenderSettings moving = settings;
  if (!moving.shutter.end_camera) moving.shutter.end_camera = camera;
  return moving;
}

void add_sample_stats(FrameStats& frame, const FrameStats& sample) {
  if (frame.samples == 0) {
    frame = sample;
    return;
  }
  add_frame_stats(frame, sample, FrameCounts::kRepeated);
  frame.samples += sample.samples;
}

}  // namespace tilesplat
