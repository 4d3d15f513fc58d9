// The runs of many frames: their plan, how each frame is written, and the resumable, sharded run with its
// manifest (render_sequence.h).
#include "render_sequence.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <future>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli.h"
#include "frame_manifest.h"
#include "frame_renderer.h"
#include "progress.h"
#include "sha256.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/lod_set.h"

namespace tilesplat::render_app {

namespace fs = std::filesystem;
using cli::single_quoted;

namespace {

// Library writers name the file in their messages; this keeps that true whatever they say.
std::string write_failure(const fs::path& path, const std::exception& error) {
  const std::string message = cli::one_line(error.what());
  if (message.find(path.filename().string()) != std::string::npos) return message;
  return "cannot write " + single_quoted(path.string()) + ": " + message;
}

// The manifest entry a finished frame gets (bytes and checksums filled when it is written).
cli::ManifestEntry manifest_entry(const Frame& frame, int frame_count, const fs::path& folder,
                                  const std::string& settings) {
  cli::ManifestEntry entry;
  entry.frame = frame.frame;
  entry.frames = frame_count;
  entry.number = frame.number;
  entry.camera = frame.description;
  entry.pose = cli::camera_pose_text(frame.camera);
  entry.width = frame.camera.width;
  entry.height = frame.camera.height;
  entry.file = frame.exr.lexically_relative(folder).string();
  if (!frame.png.empty()) entry.png = frame.png.lexically_relative(folder).string();
  entry.settings = settings;
  return entry;
}

// The frames whose manifest line matches this run's frame (same file, camera and its values, size and
// settings)
// and whose files are intact. A later line of the same frame overrides an earlier one.
std::map<int, cli::ManifestEntry> finished_frames(const std::vector<Frame>& frames, const fs::path& folder,
                                                  const std::string& settings, const cli::Shard& shard) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) return {};
  std::map<int, cli::ManifestEntry> latest;
  for (const cli::ManifestLine& line : cli::read_manifests(folder)) {
    const cli::ManifestEntry& entry = line.entry;
    if (entry.frames != static_cast<int>(frames.size()) || !shard.takes(entry.frame)) continue;
    const cli::ManifestEntry wanted =
        manifest_entry(frames[size_t(entry.frame)], static_cast<int>(frames.size()), folder, settings);
    if (entry.file == wanted.file && entry.png == wanted.png && entry.camera == wanted.camera &&
        entry.pose == wanted.pose && entry.width == wanted.width && entry.height == wanted.height &&
        entry.settings == wanted.settings && entry.number == wanted.number)
      latest[entry.frame] = entry;
  }
  std::map<int, cli::ManifestEntry> finished;
  for (const auto& [frame, entry] : latest)
    if (cli::files_match(folder, entry)) finished.emplace(frame, entry);  // else rendered again
  return finished;
}

}  // namespace

tilesplat::SaturatedValues FrameWriter::write(const Frame& frame, const tilesplat::RenderImage& image) const {
  tilesplat::ExrWriteOptions options = exr;
  options.camera = frame.camera;               // worldToCamera, worldToNDC and the exact camera
  options.display_width = frame.camera.width;  // a region's display window (--region)
  options.display_height = frame.camera.height;
  options.attributes["view"] = frame.description;
  if (frame.view_index) {
    options.attributes["viewIndex"] = std::to_string(*frame.view_index);
    options.attributes["viewName"] = frame.view_name;
  }
  tilesplat::SaturatedValues saturated;
  try {
    saturated = tilesplat::write_exr(frame.exr, image, options);
  } catch (const std::exception& error) {
    throw std::runtime_error(write_failure(frame.exr, error));
  }
  cli::print_saturation_warning(kProgram, frame.exr, saturated, options.half);
  if (!frame.png.empty()) {
    try {
      tilesplat::write_png_preview(frame.png, image, preview);
    } catch (const std::exception& error) {
      throw std::runtime_error(write_failure(frame.png, error));
    }
  }
  return saturated;
}

// The frames of a many-frame run, in order, with their files.
std::vector<Frame> plan_sequence(const cli::ArgParser& parser, const RenderOptions& options,
                                 const cli::LoadedScene& loaded) {
  const cli::CommonOptions& common = options.common;
  std::vector<Frame> frames;
  if (parser.seen("--views")) {
    const cli::SceneViews cameras = cli::camera_views(common, loaded);
    if (cameras.views.empty())
      throw cli::UsageError("--views needs cameras: " + single_quoted(loaded.path.string()) +
                            " has none of its own, and no --cameras was given");
    const std::vector<tilesplat::CameraView>& views = cameras.views;
    const fs::path& file = cameras.file;
    for (const int view :
         cli::parse_view_selection("--views", options.views, static_cast<int>(views.size()))) {
      const cli::NamedCamera named =
          cli::view_camera(views, view, file, common.width, common.height, "--views");
      frames.push_back({static_cast<int>(frames.size()),
                        view,
                        named.camera,
                        named.description,
                        view,
                        views[size_t(view)].name,
                        {},
                        {},
                        {},
                        cameras.lenses.empty() ? tilesplat::ThinLens{} : cameras.lenses[size_t(view)],
                        cameras.shutters.empty()
                            ? tilesplat::Shutter{}
                            : cli::shutter_at_size(cameras.shutters[size_t(view)], named.camera)});
    }
  } else {
    const cli::ImageSize size = cli::orbit_image_size(common.width, common.height);
    std::vector<tilesplat::Camera> cameras;
    std::string what;
    if (parser.seen("--orbit")) {
      if (loaded.gaussians() == 0)
        throw std::runtime_error(single_quoted(loaded.path.string()) +
                                 " has no Gaussians for --orbit to frame");
      cameras = tilesplat::orbit_cameras(loaded.bounds(), options.orbit_frames, size.width, size.height,
                                         common.orbit);
      what = "orbit";
    } else {
      tilesplat::CameraPath path;
      try {
        path = tilesplat::load_camera_path(options.path_file);
      } catch (const std::exception& error) {
        throw std::runtime_error("cannot read --path: " + cli::one_line(error.what()));
      }
      cameras = tilesplat::sample_camera_path(path, options.path_frames, size.width, size.height);
      what = "path " + fs::path(options.path_file).filename().string();
    }
    const bool orbit = parser.seen("--orbit");
    for (size_t f = 0; f < cameras.size(); ++f) {
      std::optional<tilesplat::Camera> next;
      if (f + 1 < cameras.size() || orbit) next = cameras[(f + 1) % cameras.size()];
      frames.push_back({static_cast<int>(f),
                        static_cast<int>(f),
                        cameras[f],
                        what + " frame " + std::to_string(f) + " of " + std::to_string(cameras.size()),
                        {},
                        {},
                        {},
                        {},
                        next});
    }
  }

  for (const auto& [flag, pattern] : {std::pair{"-o", options.output}, std::pair{"--png", options.png}})
    if (!pattern.empty() && frames.size() > 1 && !cli::has_frame_number(pattern))
      throw cli::UsageError(std::string(flag) + " " + single_quoted(pattern) +
                            " has no frame number for the " + std::to_string(frames.size()) +
                            " frames: write it as %04d (e.g. out/view_%04d.exr)");
  for (Frame& frame : frames) {
    frame.exr = cli::frame_file("-o", options.output, frame.number);
    if (!options.png.empty()) frame.png = cli::frame_file("--png", options.png, frame.number);
  }
  return frames;
}

// Renders the shard's frames that are not done yet. Frame i + 1 renders while frame i is encoded
// and written on another thread; its manifest line is appended once its files are complete. `writer` is
// a copy: the EXRs name the sort strategy the device chose.
int render_sequence(const RenderOptions& options, const std::vector<Frame>& frames, const cli::Shard& shard,
                    const cli::LoadedScene& loaded, const tilesplat::RenderSettings& settings,
                    FrameWriter writer, const std::string& settings_line) {
  fs::path folder = frames.front().exr.parent_path();
  if (folder.empty()) folder = ".";
  const int frame_count = static_cast<int>(frames.size());
  const auto finished = options.force ? std::map<int, cli::ManifestEntry>{}
                                      : finished_frames(frames, folder, settings_line, shard);
  std::vector<const Frame*> to_render;
  int in_shard = 0;
  for (const Frame& frame : frames) {
    if (!shard.takes(frame.frame)) continue;
    ++in_shard;
    if (!finished.count(frame.frame)) to_render.push_back(&frame);
  }
  if (!options.quiet) {
    std::string line = std::string(kProgram) + ": ";
    if (shard.count > 1)
      line += "shard " + std::to_string(shard.index) + "/" + std::to_string(shard.count) + " (" +
              shard.source + "): ";
    line +=
        std::to_string(in_shard) + (shard.count > 1 ? " of " + std::to_string(frame_count) : "") + " frames";
    if (!finished.empty())
      line +=
          ", " + std::to_string(finished.size()) + " already done (manifest and checksums match), skipped";
    std::fprintf(stderr, "%s\n", line.c_str());
  }

  const auto start = std::chrono::steady_clock::now();
  std::vector<double> gpu_ms;
  if (!to_render.empty()) {
    // The device first: a run that cannot create it leaves no (empty) manifest behind.
    FrameRenderer renderer(options, loaded);
    writer.exr.attributes["sortStrategy"] = renderer.sort_strategy(settings);
    cli::ManifestAppender manifest(folder / cli::manifest_file_name(shard));
    cli::FrameProgress progress(kProgram, static_cast<int>(to_render.size()),
                                cli::progress_style(options.quiet));
    std::future<void> writing;
    for (size_t index = 0; index < to_render.size(); ++index) {
      const Frame* frame = to_render[index];
      const tilesplat::Camera* next_camera =
          index + 1 < to_render.size() ? &to_render[index + 1]->camera : nullptr;
      tilesplat::RenderSettings frame_settings = settings;
      frame_settings.shutter =
          options.shutter.enabled() ? shutter_for_frame(options.shutter, frame->next_camera) : frame->shutter;
      frame_settings.lens = frame->lens;
      tilesplat::RenderImage image = renderer.render(frame->camera, frame_settings, next_camera);
      cli::ManifestEntry entry = manifest_entry(*frame, frame_count, folder, settings_line);
      entry.gpu_ms = renderer.gpu() ? renderer.gpu_ms() : renderer.cpu_ms();
      gpu_ms.push_back(entry.gpu_ms);
      if (writing.valid()) writing.get();  // rethrows the previous frame's write failure
      writing = std::async(std::launch::async,
                           [&writer, &manifest, &progress, frame, entry, image = std::move(image)]() mutable {
                             writer.write(*frame, image);
                             entry.bytes = fs::file_size(frame->exr);
                             entry.sha256 = cli::sha256_file_hex(frame->exr);
                             if (!frame->png.empty()) entry.png_sha256 = cli::sha256_file_hex(frame->png);
                             entry.resident_mib = double(cli::resident_memory_bytes()) / (1024.0 * 1024.0);
                             manifest.append(entry);
                             progress.frame_done();
                           });
    }
    writing.get();
    progress.finish();
    if (renderer.gpu())
      if (const auto messages = renderer.gpu()->validation_messages(); messages > 0)
        cli::print_warning(kProgram, std::to_string(messages) + " Vulkan validation messages (see above)");
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!options.quiet) {
    std::string line = std::string(kProgram) + ": " + loaded.path.filename().string() + ", " +
                       std::to_string(to_render.size()) + " frames rendered";
    if (!finished.empty()) line += ", " + std::to_string(finished.size()) + " skipped";
    if (!to_render.empty())
      line += " in " + cli::format_fixed(seconds, 1) + " s (" +
              cli::format_fixed(double(to_render.size()) / seconds, 2) + " frames/s, " +
              (options.reference ? "CPU reference " : "GPU ") + "median " +
              cli::format_fixed(cli::median(gpu_ms), 2) + " ms)";
    line += " -> " + (folder / cli::manifest_file_name(shard)).string();
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  return cli::kExitOk;
}

int merge(const RenderOptions& options) {
  if (!options.common.scene.empty())
    throw cli::UsageError("--merge-manifests FOLDER merges what the shards wrote and takes no SCENE");
  const cli::MergeResult result = cli::merge_manifests(options.merge_folder);
  std::fprintf(stderr, "%s: %zu shard manifests cover all %zu frames exactly once, files intact -> %s\n",
               kProgram, result.manifests, result.frames, result.merged.string().c_str());
  return cli::kExitOk;
}

}  // namespace tilesplat::render_app
