// tilesplat-render's frames and the runs of many of them: the frames of a sequence (views, an orbit, a
// path) with their files, how every frame is written (FrameWriter), and the resumable, sharded run that
// renders them with a manifest (render_sequence), whose shards' manifests merge_manifests joins. One frame
// is render_main.cpp's own.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "frame_sequence.h"
#include "render_options.h"
#include "scene_loading.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/shutter.h"

namespace tilesplat::render_app {

// One image the run writes.
struct Frame {
  int frame = 0;   // its position in the run's sequence (what shards split)
  int number = 0;  // the number in its file name: the view index, or the frame of an orbit or path
  tilesplat::Camera camera;
  std::string description;  // "view 3 (img_3) of cameras.json", "orbit frame 5 of 100", ...
  std::optional<int> view_index;
  std::string view_name;
  std::filesystem::path exr;
  std::filesystem::path png;  // empty: no preview
  // The camera one frame later, for --shutter: an orbit's next frame (the first after the last), a path's
  // (none after its last); none for the views of a camera set, which do not move from one to the next.
  std::optional<tilesplat::Camera> next_camera;
  tilesplat::ThinLens lens;    // the scene file's lens for this view (off unless it has one)
  tilesplat::Shutter shutter;  // the scene file's shutter for this view (closed unless it has one)
};

// What every frame of the run shares: the settings, the EXR and preview options and attributes.
struct FrameWriter {
  tilesplat::ExrWriteOptions exr;
  tilesplat::PreviewOptions preview;

  // Writes the EXR, then the preview (a preview must never exist without the image it previews). Returns
  // the values the EXR saturated (write_exr), which it reports on stderr in one line.
  tilesplat::SaturatedValues write(const Frame& frame, const tilesplat::RenderImage& image) const;
};

// The frames of a many-frame run, in order, with their files.
std::vector<Frame> plan_sequence(const cli::ArgParser& parser, const RenderOptions& options,
                                 const cli::LoadedScene& loaded);

// Renders the shard's frames that are not done yet (render_sequence.cpp says how); `settings_line` is what
// besides the camera makes two runs' files differ, for the manifest.
int render_sequence(const RenderOptions& options, const std::vector<Frame>& frames, const cli::Shard& shard,
                    const cli::LoadedScene& loaded, const tilesplat::RenderSettings& settings,
                    FrameWriter writer, const std::string& settings_line);

// --merge-manifests FOLDER: the shards' manifests joined into one, every frame once and its files intact.
int merge(const RenderOptions& options);

}  // namespace tilesplat::render_app
