// tilesplat-bench --sample-curve lens|time|stochastic|stochastic-stratified[:N,N...]: what an averaged
// effect's sample count costs in time, and how far its image is from the image of many samples
// (docs/effects.md), or for the stochastic compositor (its frames, with the hash or the stratified
// sampler) from the sorted frame it converges to (docs/compositors.md).
//
// One scene at the chosen views through one effect: depth of field (a thin lens of aperture 0.05 of the
// view depth of the scene's centre, focused there: the effects report's lens) or motion blur (the shutter
// open over the whole frame while the camera turns 5 degrees about the scene's centre: the effects
// report's shutter). Per sample count N: the GPU frame time (median over repeats, then views), the time
// per sample, and the PSNR and largest error against the frame of kReferenceSamples samples of the same
// effect from the same view. The frames of all rows are interleaved (row after row, repeat after
// repeat) so that a CPU driver's drifting speed affects every row alike.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat::sample_curve {

// The lens and the shutter with their even pattern (lens_samples, shutter_times) or the progressive one
// (SamplePattern::kSobol); the stochastic compositor with either sampler.
enum class Effect {
  kLens,
  kTime,
  kLensSobol,
  kTimeSobol,
  kStochastic,
  kStochasticStratified,
  kStochasticSobol,
};
// "lens", "time", "lens-sobol", "time-sobol", "stochastic", "stochastic-stratified", "stochastic-sobol"
std::string effect_name(Effect effect);
// The inverse of effect_name, or nothing.
std::optional<Effect> parse_effect(const std::string& name);
// The image the effect's frames are held to: the sorted frame for the stochastic compositor, else the
// effect with kReferenceSamples samples of the even pattern (the same image for both patterns' curves).
bool held_to_sorted_frame(Effect effect);

// The sample count the curve's images are held to (the "error against a 1,024-sample image").
constexpr int kReferenceSamples = 1024;
// The counts measured when the flag names none.
inline const std::vector<int> kDefaultCounts = {1, 2, 4, 8, 16, 32, 64, 128};

struct Row {
  int samples = 0;
  // Measured: medians (times) and means (PSNR) over the views.
  double gpu_ms = 0;
  double psnr_db = 0;  // against kReferenceSamples samples; +inf where every view is identical
  double max_abs = 0;  // the largest over the views
};

struct Options {
  Effect effect = Effect::kLens;
  std::vector<int> counts = kDefaultCounts;
  std::vector<Camera> views;
  std::array<double, 3> centre = {0, 0, 0};  // the scene's centre: the lens's focus, the camera's pivot
  int warmup = 1;
  int repeat = 5;
  std::string sort = "radix";
  RenderSettings settings;  // what every row shares besides the sort and the effect
};

// The settings of view `view` through the effect with `samples` samples.
RenderSettings effect_settings(const Options& options, const Camera& view, int samples);
// The settings of the image the effect's rows are held to from `view` (held_to_sorted_frame).
RenderSettings reference_settings(const Options& options, const Camera& view);

struct Run {
  DeviceInfo device;
  uint64_t validation_messages = 0;
};
int work_units(const Options& options);
// Renders the reference and every count at every view and returns the rows, ascending by samples.
// progress(done, total, what) as it goes.
Run measure(const RendererOptions& renderer_options, const GaussianScene& scene, const Options& options,
            std::vector<Row>& rows, const std::function<void(int, int, const std::string&)>& progress);

std::string text_table(const std::vector<Row>& rows);
std::string markdown(const std::vector<Row>& rows, Effect effect, const std::string& scene,
                     const DeviceInfo& device, const std::string& command);
std::string csv(const std::vector<Row>& rows, Effect effect, const std::string& scene,
                const DeviceInfo& device);
// PSNR against the sample count (a log axis).
std::string svg(const std::vector<Row>& rows, Effect effect, const std::string& scene,
                const DeviceInfo& device);

}  // namespace tilesplat::sample_curve
