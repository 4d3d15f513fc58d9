// tilesplat-viewer's command line: its options, their declarations and the checks that need no file
// (the window and the GPU are viewer_main.cpp's).
#pragma once

#include <string>

#include "cli.h"
#include "lens_options.h"

namespace tilesplat::viewer {

inline constexpr const char* kProgram = "tilesplat-viewer";
inline constexpr const char* kUsage = "tilesplat-viewer SCENE.ply|SCENE.json [options]";
inline constexpr const char* kDescription =
    "Shows a 3D Gaussian Splatting scene in a window. Left-drag orbits around the "
    "scene's centre, right- or "
    "middle-drag pans, the wheel zooms; N and P (or the arrow keys) step through the "
    "views of --cameras or the "
    "scene file, M cycles accuracy modes, S cycles sort strategies, C cycles the sorted, the raster and "
    "the stochastic compositor (whose frames add up while the view rests), L steps through the lenses (the "
    "pinhole, a 180-degree fisheye, the 360x180 "
    "panorama; --no-mesh), F turns depth of field on and off (--aperture or --f-stop, else an aperture of 5% "
    "of "
    "the focus distance; --no-mesh; its lens samples add up while the view rests), D turns the splats' "
    "depth out off and on, B turns motion blur off and on where the scene file's view has a shutter or its "
    "models move (--no-mesh; its time samples add up while the view rests, the view's camera motion "
    "following the camera), "
    "Esc or Q quits. The window starts at --width x --height (default 960 wide, the "
    "view's aspect) and the image "
    "follows its size. A box at the scene's centre is drawn before the splats (it hides "
    "what is behind it) and a "
    "ground grid after (the splats hide it where they are dense), as a host "
    "application's meshes would be.";

struct ViewerOptions {
  tilesplat::cli::CommonOptions common;
  int frames = 0;  // 0: until the window is closed
  double turn_deg = 0;  // --turn: degrees the camera turns about the scene each frame
  std::string screenshot;
  bool no_mesh = false;       // the splats alone, straight into the float image
  bool no_depth_out = false;  // the splats write no depth: the grid is drawn over them
  tilesplat::cli::CameraModelFlags camera_model;  // --fisheye, --orthographic, --equirectangular (key L)
  tilesplat::cli::LensFlags lens;  // depth of field, a sample a frame while the view rests (key F)
  // The stochastic compositor's thresholds (key C): hash or sobol, the samplers whose frames add up.
  tilesplat::StochasticSampler stochastic_sampler = tilesplat::StochasticSampler::kHash;
};

// Declares every flag of tilesplat-viewer.
void add_viewer_options(tilesplat::cli::ArgParser& parser, ViewerOptions& options);

// The mistakes a parsed command line can show before any file is read. Throws UsageError.
void check_viewer_flags(const tilesplat::cli::ArgParser& parser, const ViewerOptions& options);

}  // namespace tilesplat::viewer
