// The renderer for Python: the Vulkan devices, tilesplat.Renderer (render() releases the GIL while the
// frame runs; its settings are a RenderSettings and keyword overrides, settings.h) and the float64
// reference it is held to.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/unique_ptr.h>
#include <nanobind/stl/vector.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "settings.h"
#include "tilesplat/camera.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat::python {
namespace {

using namespace nb::literals;

nb::dict stats_dict(const FrameStats& stats) {
  nb::dict out;
  nb::list passes;
  for (const PassTiming& pass : stats.passes) passes.append(nb::make_tuple(pass.name, pass.gpu_ms));
  out["passes"] = passes;
  out["gpu_ms"] = stats.gpu_ms;
  out["cpu_ms"] = stats.cpu_ms;
  out["gaussians"] = stats.gaussians;
  out["visible"] = stats.visible;
  out["intersections"] = stats.intersections;
  out["sort_bits"] = stats.sort_bits;
  out["sort_strategy"] = stats.sort_strategy;
  out["retries"] = stats.retries;
  out["submissions"] = stats.submissions;
  out["device_bytes"] = stats.device_bytes;
  out["reused_sorted_lists"] = stats.reused_sorted_lists;
  out["samples"] = stats.samples;                          // frames averaged (lens, shutter)
  out["accumulated_frames"] = stats.accumulated_frames;    // the stochastic frames in the mean
  out["accumulated_samples"] = stats.accumulated_samples;  // lens and shutter samples (accumulate_samples)
  out["scene_parts"] = stats.scene_parts;                  // depth-ordered parts under a memory budget
  out["image_bands"] = stats.image_bands;                  // bands of rows of an image past the device
  out["peak_device_bytes"] = stats.peak_device_bytes;
  out["depth_order_ms"] = stats.depth_order_ms;
  out["saturated"] = saturated_dict(stats.saturated);  // channel -> values saturated (FrameStats::saturated)
  return out;
}

nb::dict device_dict(const DeviceInfo& device) {
  nb::dict out;
  out["name"] = device.name;
  out["driver"] = device.driver;
  out["subgroup_size"] = device.subgroup_size;
  out["cpu"] = device.cpu;
  out["vendor_id"] = device.vendor_id;
  out["max_image_dimension"] = device.max_image_dimension;
  out["max_allocation_size"] = device.max_allocation_size;
  out["device_memory"] = device.device_memory;
  return out;
}

// tilesplat.Renderer.
nb::class_<RendererHandle> bind_renderer_class(nb::module_& m) {
  return nb::class_<RendererHandle>(
             m, "Renderer",
             "The GPU renderer on one Vulkan device. render() releases the GIL while the frame runs.")
      .def(
          "__init__",
          [](RendererHandle* self, const std::string& device, bool validation) {
            RendererOptions options;
            options.device = device;
            options.validation = validation;
            std::unique_ptr<Renderer> renderer;
            {
              nb::gil_scoped_release release;
              renderer = Renderer::create(options);
            }
            new (self) RendererHandle{std::move(renderer)};
          },
          "device"_a = "", "validation"_a = false,
          "device: an index into devices(), part of a device's name or its UUID; '' = $TILESPLAT_DEVICE, "
          "else the "
          "first discrete GPU, else the first device. validation: the Khronos validation layer.")
      .def(
          "set_scene",
          [](RendererHandle& self, const GaussianScene& scene) {
            nb::gil_scoped_release release;
            self.renderer->set_scene(scene);
          },
          "scene"_a, "Uploads the scene (a copy: the Python scene stays free to change).")
      .def(
          "set_scene",
          [](RendererHandle& self, const SceneInstances& instances) {
            nb::gil_scoped_release release;
            self.renderer->set_scene(instances);
          },
          "instances"_a,
          "Uploads a scene file's placed copies where they are at time 0 and, when some move, keeps them (a "
          "copy): render(camera, shutter=...) then places them at each time sample, one a call with "
          "accumulate_samples=True; a closed shutter sees them at time 0.")
      .def(
          "render",
          [](RendererHandle& self, const Camera& camera, const RenderSettings* base_settings,
             const GaussianScene* scene, const LodSet* lod_set, const SceneInstances* instances,
             const SceneInParts* in_parts, const SceneInParts* mapped_ply, const nb::kwargs& overrides) {
            const RenderSettings settings = settings_with(base_settings, overrides, "render()");
            if (mapped_ply && in_parts)
              throw std::invalid_argument("render takes in_parts or mapped_ply (its earlier name), not both");
            if (mapped_ply) in_parts = mapped_ply;
            if (int(scene != nullptr) + int(lod_set != nullptr) + int(instances != nullptr) +
                    int(in_parts != nullptr) >
                1)
              throw std::invalid_argument("render takes one of scene, lod_set and instances (or in_parts)");
            if (settings.splat_budget > 0 && !lod_set)
              throw std::invalid_argument("splat_budget applies to a lod_set");
            nb::gil_scoped_release release;
            if (lod_set) return self.renderer->render(*lod_set, camera, settings);
            if (instances) return self.renderer->render(*instances, camera, settings);
            if (in_parts) return self.renderer->render(*in_parts, camera, settings);
            return scene ? self.renderer->render(*scene, camera, settings)
                         : self.renderer->render(camera, settings);
          },
          "camera"_a, "settings"_a = nb::none(), "scene"_a = nb::none(), "lod_set"_a = nb::none(),
          "instances"_a = nb::none(), "in_parts"_a = nb::none(), "mapped_ply"_a = nb::none(), "overrides"_a,
          "Renders the scene from `camera`: the one set_scene uploaded, or `scene`, which replaces it and is "
          "rendered within memory_budget bytes of device memory (0: the device's own limits), "
          "in depth-ordered parts into the same image where the whole frame would need more "
          "(docs/big-scenes.md); a LodSet `lod_set`: level 0, or under splat_budget the levels this camera "
          "calls for (LodSet.select); SceneInstances `instances`, whose moving models blur under an open "
          "shutter (with or without its end_camera); or a SceneInParts `in_parts` (`mapped_ply`, its "
          "earlier name), in parts decoded as they are drawn. "
          "settings: a RenderSettings (None: the defaults); the other keyword arguments are its fields "
          "(RenderSettings.fields), which override it: "
          "region (x, y, width, height) renders only those pixels, each the whole frame's to the bit, into "
          "an image of that size (RenderSettings::region). "
          "accuracy is a mode "
          "string ('reference', 'depth16+fp16-sh', ...), antialiasing 'classic', 'antialiased' or 'mip', "
          "compositor 'sorted', 'stochastic' or 'raster' (the depth-sorted splats drawn as quads by the "
          "graphics pipeline); stochastic_sampler 'hash', 'stratified' or 'sobol' (the stochastic "
          "compositor's "
          "thresholds: each splat's stratified over the frames, converging faster); stochastic_accumulate "
          "adds "
          "this call's frames to the previous calls' mean while the view and settings stay the same "
          "(last_frame_stats['accumulated_frames'] counts them); near_plane the view "
          "depth at or below which a Gaussian is "
          "culled; max_alpha the cap on one splat's alpha (0.99 as 3DGS trains, 0.999 as gsplat does); lens "
          "a ThinLens for depth of field (the mean of its samples' pinhole frames in linear light); shutter "
          "a "
          "Shutter for motion blur (the mean of the frames at its times); accumulate_samples renders one "
          "more sample of a 'sobol' lens and shutter a call and returns the mean of the calls' samples while "
          "the view and settings stay the same (last_frame_stats['accumulated_samples'] counts them).")
      .def_prop_ro("last_frame_stats",
                   [](const RendererHandle& self) { return stats_dict(self.renderer->last_frame_stats()); })
      .def_prop_ro("device_info",
                   [](const RendererHandle& self) { return device_dict(self.renderer->device_info()); })
      .def(
          "sort_strategy_for",
          [](const RendererHandle& self, const std::string& requested) {
            return self.renderer->sort_strategy_for(requested);
          },
          "requested"_a,
          "The strategy a requested name stands for on this device ('auto': the one it picks).")
      .def_prop_ro("validation_messages",
                   [](const RendererHandle& self) { return self.renderer->validation_messages(); });
}

// tilesplat.render_reference: the float64 frame the renderer is held to.
void bind_reference(nb::module_& m) {
  m.def(
      "render_reference",
      [](const Camera& camera, const GaussianScene* scene, const SceneInstances* instances,
         const RenderSettings* base_settings, const nb::kwargs& overrides) {
        if (int(scene != nullptr) + int(instances != nullptr) != 1)
          throw std::invalid_argument("render_reference takes one of scene and instances");
        const RenderSettings settings = settings_with(base_settings, overrides, "render_reference()");
        nb::gil_scoped_release release;
        return instances ? render_reference(*instances, camera, settings)
                         : render_reference(*scene, camera, settings);
      },
      "camera"_a, "scene"_a = nb::none(), "instances"_a = nb::none(), "settings"_a = nb::none(),
      "overrides"_a,
      "The float64 CPU reference the GPU renderer is held to (docs/rendering-math.md): the frame of `scene` "
      "(or SceneInstances `instances`) from `camera`, in double precision on the host's cores, with "
      "Renderer.render's settings and keywords that apply to it (compositor 'sorted' or 'raster', whose rule "
      "it has; accuracy modes such as 'resort16' change its per-pixel order). Slow: seconds for a small "
      "image of a real scene. Releases the GIL.");
}

}  // namespace

void bind_renderer(nb::module_& m) {
  m.def("devices", &list_devices, "The Vulkan devices, in the order Renderer(device=INDEX) counts them.");
  m.def("sort_strategies", &sort_strategies,
        "The sort strategies Renderer.render(sort=...) accepts, besides auto.");

  nb::class_<RendererHandle> renderer = bind_renderer_class(m);
  bind_reference(m);
  bind_gradients(m, renderer);
}

}  // namespace tilesplat::python
