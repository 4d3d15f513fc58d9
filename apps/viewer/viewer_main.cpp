// tilesplat-viewer: a window onto a scene. The engine renders on the window's own Vulkan device
// (tilesplat/vulkan_interop.h), submitting each frame without waiting for it, into an image this app
// owns: with the mesh (viewer/mesh_layer.h), between a box it draws first, whose depth cuts the splats,
// and a ground grid it draws after, hidden behind the splats' depth; without it (--no-mesh), into a
// float image alone. Each frame is then blitted to the window's swapchain. Nothing is rendered while
// nothing changes: the loop then sleeps in glfwWaitEvents, so an idle viewer costs nothing.
#include <GLFW/glfw3.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "cli.h"
#include "lod_view.h"
#include "mesh_layer.h"
#include "orbit_controller.h"
#include "swapchain.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/vulkan_interop.h"
#include "view_effects.h"
#include "view_state.h"
#include "viewer_options.h"
#include "window_device.h"

namespace {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;
using tilesplat::viewer::FloatImage;
using tilesplat::viewer::MeshLayer;
using tilesplat::viewer::Swapchain;
using tilesplat::viewer::WindowDevice;

using namespace tilesplat::viewer;
constexpr int kDefaultWindowWidth = 960;  // the height follows the view's aspect
// The stochastic frames a view at rest accumulates before the window stops redrawing it (about 40 dB
// from the sorted image on the bundled scenes: docs/compositors.md).
constexpr uint32_t kMaxAccumulatedFrames = 256;
bool validation_from_environment() {
  const char* value = std::getenv("TILESPLAT_VALIDATION");
  return value && *value && std::string_view(value) != "0";
}

// GLFW reports why a call failed through a callback; the last report goes into the error message.
std::string last_glfw_error;
void record_glfw_error(int, const char* description) { last_glfw_error = description; }

// glfwInit to glfwTerminate.
class GlfwSession {
 public:
  GlfwSession() {
    glfwSetErrorCallback(record_glfw_error);
    if (!glfwInit())
      throw std::runtime_error("cannot open a window: " + last_glfw_error +
                               " (no display? set DISPLAY, or run it under xvfb-run)");
    if (!glfwVulkanSupported()) {
      glfwTerminate();
      throw std::runtime_error("cannot open a window: GLFW finds no Vulkan loader with surface support");
    }
  }
  ~GlfwSession() { glfwTerminate(); }
  GlfwSession(const GlfwSession&) = delete;
  GlfwSession& operator=(const GlfwSession&) = delete;
};

using WindowHandle = std::unique_ptr<GLFWwindow, decltype(&glfwDestroyWindow)>;

// How the viewer schedules and shows its frames: the loop that renders when what is shown (ViewState)
// changes, or while a view at rest refines, and sleeps otherwise; the window's swapchain and the images
// it is fed from, which follow the window's size; the levels streamed under --splat-budget; the title.
class Viewer {
 public:
  Viewer(GLFWwindow* window, const WindowDevice& device, tilesplat::Renderer& renderer,
         const ViewerOptions& options, const cli::LoadedScene& loaded, cli::SceneViews views)
      : window_(window),
        device_(device),
        renderer_(renderer),
        swapchain_(device),
        view_(options, loaded, std::move(views)),
        mesh_(!options.no_mesh),
        turn_deg_(options.turn_deg),
        lod_view_(
            loaded.lod && loaded.lod->splat_budget > 0
                ? std::make_unique<LodView>(*loaded.lod->set, loaded.lod->splat_budget, glfwPostEmptyEvent)
            : loaded.lod_tree && loaded.lod_tree->splat_budget > 0
                ? std::make_unique<LodView>(*loaded.lod_tree->tree, loaded.lod_tree->splat_budget)
                : nullptr) {
    glfwSetWindowUserPointer(window_, this);
    glfwSetKeyCallback(window_, on_key);
    glfwSetMouseButtonCallback(window_, on_mouse_button);
    glfwSetCursorPosCallback(window_, on_cursor);
    glfwSetScrollCallback(window_, on_scroll);
    glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int, int) { self(w).resized_ = true; });
    // The window was uncovered: show the last frame again, which needs no render.
    glfwSetWindowRefreshCallback(window_, [](GLFWwindow* w) { self(w).needs_present_ = true; });
  }

  // The renderer's last frame may still run, into this viewer's images.
  ~Viewer() {
    try {
      tilesplat::wait_for_frame(renderer_);
    } catch (const std::exception&) {  // an error of that frame's: nothing more to do with it
    }
  }

  // Runs until the window closes (Esc, Q, the close button), or for `frame_limit` frames when it is
  // positive, each of which is rendered even if nothing changed.
  void run(int frame_limit) {
    while (!glfwWindowShouldClose(window_)) {
      if (frame_limit > 0 || turn_deg_ != 0) needs_render_ = true;
      if ((needs_render_ || needs_present_ || swapchain_.stale()) && !minimized_)
        glfwPollEvents();
      else
        glfwWaitEvents();
      if (lod_view_ && lod_view_->arrived()) needs_render_ = true;  // the camera's levels were read
      if (resized_ || swapchain_.stale()) fit_to_window();
      if (minimized_) continue;
      const auto start = std::chrono::steady_clock::now();
      const bool rendering = needs_render_;
      if (rendering && turn_deg_ != 0 && frames_ > 0) view_.controller().turn(turn_deg_);
      if (rendering) render();
      if (needs_present_) needs_present_ = !present();
      if (rendering) {
        const double frame_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (frames_ > 1) {  // the first frame builds pipelines
          frame_ms_total_ += frame_ms;
          frame_ms_max_ = std::max(frame_ms_max_, frame_ms);
        }
        show_title(frame_ms);
        if (frame_limit > 0 && frames_ >= frame_limit) break;
      }
    }
  }

  // The camera and settings of the last frame, for a screenshot.
  tilesplat::Camera camera() const { return view_.camera(); }
  // The settings of the window's last frame as one render: the stochastic frames it had accumulated
  // in one call (the same image: N calls of 1 frame are 1 call of N).
  tilesplat::RenderSettings screenshot_settings() {
    tilesplat::RenderSettings shot = view_.settings();
    if (shot.accumulate_samples) {  // the lens or time samples on screen
      tilesplat::wait_for_frame(renderer_);
      screenshot_samples_ = int(std::max(1u, renderer_.last_frame_stats().accumulated_samples));
      shot = tilesplat::viewer::screenshot_settings(shot, screenshot_samples_);
    }
    if (shot.compositor == tilesplat::Compositor::kStochastic) {
      tilesplat::wait_for_frame(renderer_);
      shot.stochastic.frames = std::max(1u, renderer_.last_frame_stats().accumulated_frames);
      shot.stochastic.accumulate = false;
    }
    return shot;
  }
  int frames() const { return frames_; }
  // Under --splat-budget, the last camera's levels on the device, read to the end (an EXR screenshot is
  // the frame of those levels, as tilesplat-render draws it, not of the ones still shown while loading).
  void finish_streaming() {
    if (lod_view_) lod_view_->finish(renderer_);
  }
  // The samples the last frame had added up (screenshot_settings).
  int screenshot_samples() const { return screenshot_samples_; }
  VkFormat window_format() const { return swapchain_.format(); }
  // The mean wall time of a frame (render and present) after the first; 0 before the second.
  double mean_frame_ms() const { return frames_ > 1 ? frame_ms_total_ / (frames_ - 1) : 0.0; }
  double slowest_frame_ms() const { return frame_ms_max_; }  // after the first; 0 before the second
  // Under --splat-budget: how often the levels were read and how long each read took.
  std::string lod_summary() const { return lod_view_ ? lod_view_->summary() : ""; }

  // What the window shows now: the last frame presented once more, its bytes read back from the
  // window's image.
  tilesplat::viewer::WindowPixels window_pixels() {
    tilesplat::wait_for_frame(renderer_);
    tilesplat::viewer::WindowPixels shown;
    const VkImage source = mesh_layer_ ? mesh_layer_->picture() : image_->image();
    const VkImageLayout layout = mesh_layer_ ? MeshLayer::kPictureLayout : FloatImage::kLayout;
    if (!swapchain_.present(source, layout, shown_extent_, &shown))
      throw std::runtime_error("the window could not show the last frame again for the screenshot");
    return shown;
  }

 private:
  static Viewer& self(GLFWwindow* window) { return *static_cast<Viewer*>(glfwGetWindowUserPointer(window)); }

  // The callbacks run inside glfwPollEvents/glfwWaitEvents (C code): they only change state, and
  // the loop does the work that can throw.
  static void on_key(GLFWwindow* window, int key, int, int action, int) {
    if (action == GLFW_RELEASE) return;
    if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q)
      glfwSetWindowShouldClose(window, GLFW_TRUE);
    else if (self(window).view_.press(key))
      self(window).needs_render_ = true;
  }

  static void on_mouse_button(GLFWwindow* window, int button, int action, int) {
    Viewer& viewer = self(window);
    if (action == GLFW_PRESS) {
      viewer.drag_button_ = button;
      glfwGetCursorPos(window, &viewer.cursor_x_, &viewer.cursor_y_);
    } else if (button == viewer.drag_button_) {
      viewer.drag_button_ = -1;
    }
  }

  static void on_cursor(GLFWwindow* window, double x, double y) {
    Viewer& viewer = self(window);
    if (viewer.drag_button_ < 0) return;
    // Cursor positions are in window coordinates; the camera is in framebuffer pixels.
    int window_width = 0, framebuffer_width = 0;
    glfwGetWindowSize(window, &window_width, nullptr);
    glfwGetFramebufferSize(window, &framebuffer_width, nullptr);
    const double scale = window_width > 0 ? double(framebuffer_width) / window_width : 1.0;
    const double dx = (x - viewer.cursor_x_) * scale, dy = (y - viewer.cursor_y_) * scale;
    viewer.cursor_x_ = x;
    viewer.cursor_y_ = y;
    if (viewer.drag_button_ == GLFW_MOUSE_BUTTON_LEFT)
      viewer.view_.controller().orbit(dx, dy);
    else
      viewer.view_.controller().pan(dx, dy);
    viewer.needs_render_ = true;
  }

  static void on_scroll(GLFWwindow* window, double, double steps) {
    self(window).view_.controller().zoom(steps);
    self(window).needs_render_ = true;
  }

  // The swapchain, the images and the camera follow the framebuffer; a 0x0 one (minimized) has no
  // swapchain images, and the loop sleeps until it grows again.
  void fit_to_window() {
    resized_ = false;
    int width = 0, height = 0;
    glfwGetFramebufferSize(window_, &width, &height);
    swapchain_.recreate(uint32_t(std::max(width, 0)), uint32_t(std::max(height, 0)));
    const VkExtent2D extent = swapchain_.extent();
    minimized_ = extent.width == 0 || extent.height == 0;
    if (minimized_ || (shown_extent_.width == extent.width && shown_extent_.height == extent.height)) return;
    tilesplat::wait_for_frame(renderer_);  // it may still write into the images
    image_.reset();
    mesh_layer_.reset();
    if (mesh_)
      mesh_layer_ = std::make_unique<MeshLayer>(device_, view_.bounds(), extent.width, extent.height);
    else
      image_ = std::make_unique<FloatImage>(device_, extent.width, extent.height);
    shown_extent_ = extent;
    view_.controller().resize(int(extent.width), int(extent.height));
    needs_render_ = true;
  }

  void render() {
    if (lod_view_) lod_view_->prepare_frame(renderer_, view_.camera());
    tilesplat::RenderSettings frame = view_.settings();
    frame.depth = frame.splat_count = false;  // the window shows colour alone
    // Submitted without waiting (HostFrameSync): the presentation's blit is queued behind it.
    if (mesh_layer_)
      mesh_layer_->draw(renderer_, view_.pinhole_camera(), frame, view_.depth_out());
    else
      tilesplat::render_to_image(renderer_, view_.camera(), frame, image_->target(), nullptr,
                                 tilesplat::HostFrameSync{});
    // A view at rest goes on refining: its lens samples up to --lens-samples and its time samples up to
    // the shutter's, or the stochastic compositor's frames up to kMaxAccumulatedFrames (the counts lag a
    // frame: the last frame's statistics arrive when the next one starts).
    const tilesplat::FrameStats& last = renderer_.last_frame_stats();
    if (frame.accumulate_samples)
      needs_render_ = last.accumulated_samples + 1 < uint32_t(tilesplat::viewer::samples_to_add_up(frame));
    else
      needs_render_ = frame.compositor == tilesplat::Compositor::kStochastic &&
                      last.accumulated_frames + 1 < kMaxAccumulatedFrames;
    needs_present_ = true;
    ++frames_;
  }

  bool present() {
    if (mesh_layer_)
      return swapchain_.present(mesh_layer_->picture(), MeshLayer::kPictureLayout, shown_extent_);
    return swapchain_.present(image_->image(), FloatImage::kLayout, shown_extent_);
  }

  // The GPU time is the previous frame's: a frame's statistics come once it has been waited for.
  void show_title(double frame_ms) {
    const tilesplat::FrameStats& last = renderer_.last_frame_stats();
    std::string title = view_.title(last) + (lod_view_ ? lod_view_->title() : "") + " | GPU " +
                        cli::format_fixed(last.gpu_ms, 1) + " ms | frame " + cli::format_fixed(frame_ms, 1) +
                        " ms (" + cli::format_fixed(1000.0 / std::max(frame_ms, 1e-3), 1) + " fps)";
    if (mesh_layer_ && !MeshLayer::depth_testable(view_.settings()))
      title += " | mesh off: this mode does not depth-test";
    else if (mesh_layer_ && !view_.depth_out())
      title += " | no depth out";
    else if (mesh_layer_ && !mesh_layer_->writes_depth_out(view_.settings()))
      title += " | no depth out: this device's raster compositor writes none";
    glfwSetWindowTitle(window_, title.c_str());
  }

  GLFWwindow* window_;
  const WindowDevice& device_;
  tilesplat::Renderer& renderer_;
  std::unique_ptr<FloatImage> image_;      // --no-mesh: the splats alone, the swapchain's size
  std::unique_ptr<MeshLayer> mesh_layer_;  // else the box, the splats and the grid
  VkExtent2D shown_extent_{0, 0};          // the size of the images above
  Swapchain swapchain_;                    // destroyed first: it waits for the device to be idle
  ViewState view_;                         // what is shown
  bool mesh_;                              // draw the box and the grid (not --no-mesh)
  double turn_deg_;                        // --turn: degrees the camera turns each frame
  std::unique_ptr<LodView> lod_view_;      // a LOD set drawn under --splat-budget, else null
  int screenshot_samples_ = 0;

  int drag_button_ = -1;  // the mouse button held, or -1
  double cursor_x_ = 0, cursor_y_ = 0;
  bool needs_render_ = true;
  bool needs_present_ = false;
  bool resized_ = true;
  bool minimized_ = false;
  int frames_ = 0;
  double frame_ms_total_ = 0;  // over the frames after the first
  double frame_ms_max_ = 0;    // the slowest of them
};

// A PNG is the window's pixels as shown (the mesh included; the bytes of the window's image, which
// are the trained colours as a PNG preview without exposure or tone curve holds them). An EXR is the last
// frame's data: its camera and settings rendered once more (only the composite runs: the lists are reused),
// with the outputs the EXR carries, exactly as tilesplat-render writes them.
void write_screenshot(const fs::path& path, tilesplat::Renderer& renderer, Viewer& viewer,
                      const cli::LoadedScene& loaded) {
  if (cli::has_extension(path, ".png")) {
    const tilesplat::viewer::WindowPixels shown = viewer.window_pixels();
    // The bytes through write_png_preview unchanged: round(255 * (b / 255)) is b.
    tilesplat::RenderImage image;
    image.width = int(shown.width);
    image.height = int(shown.height);
    image.rgba.assign(4 * image.pixels(), 1.0f);
    for (size_t pixel = 0; pixel < image.pixels(); ++pixel)
      for (size_t c = 0; c < 3; ++c) image.rgba[4 * pixel + c] = float(shown.rgb[3 * pixel + c]) / 255.0f;
    tilesplat::write_png_preview(path, image);
  } else {
    viewer.finish_streaming();
    const tilesplat::RenderSettings settings = viewer.screenshot_settings();
    const tilesplat::RenderImage image = tilesplat::viewer::render_screenshot(
        renderer, viewer.camera(), settings, viewer.screenshot_samples());
    if (settings.compositor == tilesplat::Compositor::kStochastic)
      std::fprintf(stderr, "%s: the screenshot is the mean of %u stochastic frames\n", kProgram,
                   settings.stochastic.frames);
    if (settings.lens.enabled() || settings.shutter.opens())
      std::fprintf(stderr, "%s: the screenshot is the mean of %d %s samples\n", kProgram,
                   viewer.screenshot_samples(),
                   settings.lens.enabled() && settings.shutter.opens() ? "joint lens and time"
                   : settings.lens.enabled()                           ? "lens"
                                                                       : "time");
    tilesplat::ExrWriteOptions exr;
    exr.alpha = !loaded.description || loaded.description->outputs.alpha;
    exr.camera = viewer.camera();
    // Empty pixels far away; over a background, an opaque frame (as tilesplat-render writes them).
    exr.empty_depth = tilesplat::kFarDepth;
    exr.opaque_alpha = settings.background != std::array<float, 3>{0, 0, 0};
    cli::print_saturation_warning(kProgram, path, tilesplat::write_exr(path, image, exr), exr.half);
  }
}

int run(int argc, char** argv) {
  cli::load_sort_plugins(argc, argv);  // before the parser lists and checks the sort names
  ViewerOptions options;
  cli::ArgParser parser(kProgram, kUsage, kDescription);
  add_viewer_options(parser, options);
  if (cli::parse_and_handle_info_flags(parser, argc, argv, options.common)) return cli::kExitOk;
  check_viewer_flags(parser, options);
  if (!options.screenshot.empty()) cli::check_output_path(options.screenshot, "--screenshot");
  if (!parser.seen("--width") && !parser.seen("--height")) options.common.width = kDefaultWindowWidth;
  options.common.validation = options.common.validation || validation_from_environment();

  // The scene and cameras before the window: a bad file fails without one flashing up.
  // A scene file whose models move is kept as placed copies, which the renderer places at each time
  // sample of motion blur (key B).
  const cli::LoadedScene loaded =
      cli::load_scene_and_camera(options.common, kProgram, cli::SceneHolding::kInstancesIfMoving);
  cli::SceneViews views = cli::camera_views(options.common, loaded);

  GlfwSession glfw;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);  // Vulkan presents; no OpenGL context
  const WindowHandle window(
      glfwCreateWindow(loaded.camera.width, loaded.camera.height, kProgram, nullptr, nullptr), glfwDestroyWindow);
  if (!window) throw std::runtime_error("cannot open a window: " + last_glfw_error);
  const WindowDevice device(window.get(), options.common.validation, options.common.device);
  const auto renderer = tilesplat::create_renderer(device.external());
  if (loaded.instances)
    renderer->set_scene(*loaded.instances);
  else if ((!loaded.lod || loaded.lod->splat_budget == 0) && (!loaded.lod_tree || loaded.lod_tree->splat_budget == 0))
    renderer->set_scene(loaded.scene);  // else per frame

  Viewer viewer(window.get(), device, *renderer, options, loaded, std::move(views));
  viewer.run(options.frames);
  tilesplat::wait_for_frame(*renderer);                            // the last frame's statistics
  const double last_gpu_ms = renderer->last_frame_stats().gpu_ms;  // before a screenshot renders again
  if (!options.screenshot.empty()) {
    if (viewer.frames() == 0)
      throw std::runtime_error("the window closed before a frame was rendered; " + options.screenshot +
                               " was not written");
    write_screenshot(options.screenshot, *renderer, viewer, loaded);
  }

  const tilesplat::Camera& camera = viewer.camera();
  std::string summary = std::string(kProgram) + ": " + loaded.path.filename().string() + ", " +
                        cli::describe_scene(loaded) + ", " + std::to_string(viewer.frames()) +
                        (viewer.frames() == 1 ? " frame on " : " frames on ") + device.name() + " in a " +
                        tilesplat::viewer::format_name(viewer.window_format()) + " window, the last " +
                        cli::format_size(camera.width, camera.height) + " in " +
                        cli::format_fixed(last_gpu_ms, 2) + " GPU ms";
  if (viewer.frames() > 1)
    summary += ", " + cli::format_fixed(viewer.mean_frame_ms(), 1) +
               " ms a frame after the first (the slowest " + cli::format_fixed(viewer.slowest_frame_ms(), 1) +
               " ms)";
  summary += viewer.lod_summary();
  if (device.validation()) summary += ", validation: " + std::to_string(device.validation_messages()) + " messages";
  if (!options.screenshot.empty()) summary += " -> " + options.screenshot;
  std::fputs((summary + "\n").c_str(), stderr);
  if (device.validation_messages() > 0)
    cli::print_warning(kProgram, std::to_string(device.validation_messages()) +
                                     " Vulkan validation messages (see above)");
  return cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
