#include "viewer_options.h"

#include <cmath>

namespace tilesplat::viewer {

namespace cli = tilesplat::cli;

void add_viewer_options(cli::ArgParser& parser, ViewerOptions& options) {
  cli::add_common_options(parser, options.common, cli::SortChoice::kOne);
  cli::add_splat_budget_option(parser, options.common);
  cli::add_camera_model_options(parser, options.camera_model);
  cli::add_lens_options(parser, options.lens,
                        "lens samples a still view adds up, one a frame (1 to 4096, default 32)");
  parser.add_value(
      "--stochastic-sampler", "NAME",
      "how the stochastic compositor (key C) draws its thresholds: hash (independent frames, the "
      "default) or sobol (the effects' progressive sequence: stratified at powers of two, so a "
      "still view converges faster)",
      [&options](const std::string& text) {
        if (text == "hash" || text == "sobol") {
          options.stochastic_sampler = parse_stochastic_sampler(text);
          return;
        }
        throw cli::UsageError(
            "--stochastic-sampler must be hash or sobol (stratified needs the frame count "
            "before the first frame, and a still view's frames add up one by one), got " +
            cli::single_quoted(text));
      });
  parser.section("scripting");
  parser.add_int("--frames", "N", "render N frames, then exit (default: run until the window is closed)",
                 &options.frames, 1, 1000000);
  parser.add_double("--turn", "DEG",
                    "turn the camera DEG degrees about the scene's vertical axis every frame, as a steady "
                    "horizontal drag (a turntable; with --frames, a scripted orbit)",
                    &options.turn_deg);
  parser.add_string(
      "--screenshot", "FILE",
      "on exit, write the last frame: an .exr of the splats as tilesplat-render writes it, or a .png "
      "of the window as shown",
      &options.screenshot);
  parser.section("mesh");
  parser.add_switch("--no-mesh", "show the splats alone, without the box and the grid", &options.no_mesh);
  parser.add_switch("--no-depth-out", "the splats write no depth, so the grid is drawn over them (key D)",
                    &options.no_depth_out);
}

void check_viewer_flags(const cli::ArgParser& parser, const ViewerOptions& options) {
  cli::check_common_options(parser, options.common);
  if (parser.seen("--lod") && parser.seen("--splat-budget"))
    throw cli::UsageError(
        "--lod draws one level of a LOD set and --splat-budget chooses the levels per frame: one of them");
  // The compositors the window shows (key C), checked before a window opens.
  if (options.common.compositor == Compositor::kStochastic && !options.common.modes.empty() &&
      !compositor_draws(Compositor::kStochastic, options.common.modes.front()))
    throw cli::UsageError("the stochastic compositor sorts nothing (--mode " +
                          to_string(options.common.modes.front()) + ")");
  if (options.common.compositor == Compositor::kRaster && !options.common.modes.empty() &&
      !compositor_draws(Compositor::kRaster, options.common.modes.front()))
    throw cli::UsageError("the raster compositor does not re-sort per pixel (--mode " +
                          to_string(options.common.modes.front()) + ")");
  if (std::abs(options.turn_deg) > 180.0)
    throw cli::UsageError("--turn must be between -180 and 180 degrees a frame, got " +
                          cli::format_fixed(options.turn_deg, 1));
  cli::check_camera_model_options(options.camera_model);
  // The box and the grid are drawn through a pinhole, and the splats test against their depth.
  if (options.camera_model.enabled() && !options.no_mesh)
    throw cli::UsageError(
        "--fisheye, --orthographic and --equirectangular show the splats alone: add --no-mesh (the box "
        "and the grid are drawn through a pinhole)");
  cli::check_lens_options(parser, options.lens);
  // Depth of field does not test against the box's depth (a host's depth is the pinhole's).
  if (options.lens.enabled() && !options.no_mesh)
    throw cli::UsageError(
        "depth of field (--aperture, --f-stop) shows the splats alone: add --no-mesh (the box and the grid "
        "are drawn through a pinhole)");
  if (options.lens.enabled() && options.camera_model.enabled())
    throw cli::UsageError("depth of field (--aperture, --f-stop) needs a pinhole camera, not " +
                          std::string(options.camera_model.fisheye_fov_deg ? "--fisheye"
                                      : options.camera_model.view_height   ? "--orthographic"
                                                                           : "--equirectangular"));
  // The lens's rule (camera_draws) on the lens alone: no scene's camera is loaded yet.
  if (!options.common.modes.empty() &&
      !camera_draws(cli::camera_for_frame(options.camera_model, Camera{}), options.common.modes.front())) {
    const AccuracyModes& modes = options.common.modes.front();
    if (modes.resort_window > 0)
      throw cli::UsageError("per-pixel re-sorting (--mode " + to_string(modes) +
                            ") needs the pinhole camera");
    throw cli::UsageError("radial sorting (--mode " + to_string(modes) +
                          ") measures from the camera's centre, which --orthographic does not have");
  }
  if (!options.screenshot.empty()) {
    if (!cli::has_extension(options.screenshot, ".exr") && !cli::has_extension(options.screenshot, ".png"))
      throw cli::UsageError("--screenshot expects an .exr or .png file, got '" + options.screenshot + "'");
    cli::check_distinct_paths({{"SCENE", options.common.scene},
                               {"--cameras", options.common.cameras},
                               {"--screenshot", options.screenshot}});
  }
}

}  // namespace tilesplat::viewer
