// tilesplat.RenderSettings (settings.h): one table of fields, each a name (Renderer.render()'s keyword),
// a getter and a setter over the C++ RenderSettings, whose defaults are the class's. The setters check
// with the engine's own parsers (accuracy modes, region) or the engine's names of the choices; what the
// frame as a whole must satisfy (a lens with a compositor, a budget with a scene) is checked by the
// renderer when it renders, as in C++.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <array>
#include <optional>
#include <string>

#include "settings.h"
#include "tilesplat/lens.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/shutter.h"

namespace tilesplat::python {
namespace {

using namespace nb::literals;

// `value` as a T, or TypeError "RenderSettings.NAME must be EXPECTED, got TYPE".
template <typename T>
T cast_field(nb::handle value, const char* name, const char* expected) {
  try {
    return nb::cast<T>(value);
  } catch (const nb::cast_error&) {
    const std::string message = std::string("RenderSettings.") + name + " must be " + expected + ", got " +
                                nb::type_name(value.type()).c_str();
    throw nb::type_error(message.c_str());
  }
}

// One field of RenderSettings as Python sees it.
struct Field {
  const char* name;  // the property's name and render()'s keyword
  const char* doc;
  nb::object (*get)(const RenderSettings&);
  void (*set)(RenderSettings&, nb::handle);
};

// The choices of the enum fields, named by the engine's to_string.
constexpr std::array kAntialiasing{Antialiasing::kClassic, Antialiasing::kAntialiased, Antialiasing::kMip};
constexpr std::array kCompositors{Compositor::kSorted, Compositor::kStochastic, Compositor::kRaster};
constexpr std::array kSamplers{StochasticSampler::kHash, StochasticSampler::kStratified,
                               StochasticSampler::kSobol};

// The fields, in the order of Renderer.render()'s keywords before this class existed.
const std::array kFields{
    Field{"sort",
          "a name of sort_strategies(), or 'auto' (the default): the fastest exact strategy for the "
          "renderer's device; the images are the same to the bit whatever it picks",
          [](const RenderSettings& s) { return nb::cast(s.sort); },
          [](RenderSettings& s, nb::handle v) { s.sort = cast_field<std::string>(v, "sort", "a str"); }},
    Field{"depth", "produce the expected-depth channel (Image.depth)",
          [](const RenderSettings& s) { return nb::cast(s.depth); },
          [](RenderSettings& s, nb::handle v) { s.depth = cast_field<bool>(v, "depth", "a bool"); }},
    Field{"splat_count", "produce the per-pixel count of blended splats (Image.splat_count)",
          [](const RenderSettings& s) { return nb::cast(s.splat_count); },
          [](RenderSettings& s, nb::handle v) {
            s.splat_count = cast_field<bool>(v, "splat_count", "a bool");
          }},
    Field{"accuracy",
          "the accuracy modes, 'reference' or modes joined by '+' ('depth16+fp16-sh', 'resort16', 'radial', "
          "...: docs/accuracy.md)",
          [](const RenderSettings& s) { return nb::cast(to_string(s.accuracy)); },
          [](RenderSettings& s, nb::handle v) {
            s.accuracy = parse_accuracy_modes(cast_field<std::string>(v, "accuracy", "a str"));
          }},
    Field{"antialiasing",
          "the footprint filter the asset was trained with: 'classic', 'antialiased' or 'mip'",
          [](const RenderSettings& s) { return nb::cast(to_string(s.antialiasing)); },
          [](RenderSettings& s, nb::handle v) {
            s.antialiasing = parse_choice("antialiasing", cast_field<std::string>(v, "antialiasing", "a str"),
                                          kAntialiasing);
          }},
    Field{"compositor",
          "'sorted', 'stochastic' or 'raster' (the depth-sorted splats drawn as quads by the graphics "
          "pipeline)",
          [](const RenderSettings& s) { return nb::cast(to_string(s.compositor)); },
          [](RenderSettings& s, nb::handle v) {
            s.compositor =
                parse_choice("compositor", cast_field<std::string>(v, "compositor", "a str"), kCompositors);
          }},
    Field{"stochastic_frames", "the stochastic compositor's frames averaged by one render(), 1 to 4096",
          [](const RenderSettings& s) { return nb::cast(s.stochastic.frames); },
          [](RenderSettings& s, nb::handle v) {
            s.stochastic.frames = cast_field<uint32_t>(v, "stochastic_frames", "a non-negative int");
          }},
    Field{"seed", "the stochastic compositor's seed: equal seeds give bit-identical images",
          [](const RenderSettings& s) { return nb::cast(s.stochastic.seed); },
          [](RenderSettings& s, nb::handle v) {
            s.stochastic.seed = cast_field<uint32_t>(v, "seed", "a non-negative int");
          }},
    Field{"stochastic_sampler",
          "the stochastic compositor's thresholds: 'hash', 'stratified' or 'sobol' (each splat's stratified "
          "over the frames, converging faster)",
          [](const RenderSettings& s) { return nb::cast(to_string(s.stochastic.sampler)); },
          [](RenderSettings& s, nb::handle v) {
            s.stochastic.sampler = parse_choice(
                "stochastic_sampler", cast_field<std::string>(v, "stochastic_sampler", "a str"), kSamplers);
          }},
    Field{"stochastic_accumulate",
          "add this call's stochastic frames to the previous calls' mean while the view and settings stay "
          "the same (last_frame_stats['accumulated_frames'] counts them)",
          [](const RenderSettings& s) { return nb::cast(s.stochastic.accumulate); },
          [](RenderSettings& s, nb::handle v) {
            s.stochastic.accumulate = cast_field<bool>(v, "stochastic_accumulate", "a bool");
          }},
    Field{"background", "RGB behind the splats, in the splats' display values (docs/colour.md)",
          [](const RenderSettings& s) { return nb::cast(s.background); },
          [](RenderSettings& s, nb::handle v) {
            s.background = cast_field<std::array<float, 3>>(v, "background", "3 numbers");
          }},
    Field{"reuse_lists",
          "run only the composite when the frame's tile lists equal the previous frame's; False: always "
          "build them, as a benchmark of whole frames needs",
          [](const RenderSettings& s) { return nb::cast(s.reuse_lists); },
          [](RenderSettings& s, nb::handle v) {
            s.reuse_lists = cast_field<bool>(v, "reuse_lists", "a bool");
          }},
    Field{"near_plane", "the view depth at or below which a Gaussian is culled (0.2 as 3DGS trains)",
          [](const RenderSettings& s) { return nb::cast(s.near_plane); },
          [](RenderSettings& s, nb::handle v) {
            s.near_plane = cast_field<double>(v, "near_plane", "a number");
          }},
    Field{"max_alpha", "the cap on one splat's alpha (0.99 as 3DGS trains, 0.999 as gsplat does)",
          [](const RenderSettings& s) { return nb::cast(s.max_alpha); },
          [](RenderSettings& s, nb::handle v) {
            s.max_alpha = cast_field<double>(v, "max_alpha", "a number");
          }},
    Field{"lens",
          "a ThinLens for depth of field (the mean of its samples' pinhole frames in linear light), or None "
          "(the pinhole); reads None while it is the pinhole",
          [](const RenderSettings& s) {
            return s.lens == ThinLens{} ? nb::object(nb::none()) : nb::cast(s.lens);
          },
          [](RenderSettings& s, nb::handle v) {
            s.lens = v.is_none() ? ThinLens{} : cast_field<ThinLens>(v, "lens", "a ThinLens or None");
          }},
    Field{"shutter",
          "a Shutter for motion blur (the mean of the frames at its times), or None (closed); reads None "
          "while it is closed",
          [](const RenderSettings& s) {
            return s.shutter == Shutter{} ? nb::object(nb::none()) : nb::cast(s.shutter);
          },
          [](RenderSettings& s, nb::handle v) {
            s.shutter = v.is_none() ? Shutter{} : cast_field<Shutter>(v, "shutter", "a Shutter or None");
          }},
    Field{"accumulate_samples",
          "render one more sample of a 'sobol' lens and shutter a call and return the mean of the calls' "
          "samples while the view and settings stay the same (last_frame_stats['accumulated_samples'])",
          [](const RenderSettings& s) { return nb::cast(s.accumulate_samples); },
          [](RenderSettings& s, nb::handle v) {
            s.accumulate_samples = cast_field<bool>(v, "accumulate_samples", "a bool");
          }},
    Field{"memory_budget",
          "device memory in bytes a frame of a scene may hold, past which it is rendered in depth-ordered "
          "parts (docs/big-scenes.md); 0: the device's own limits",
          [](const RenderSettings& s) { return nb::cast(s.memory_budget); },
          [](RenderSettings& s, nb::handle v) {
            s.memory_budget = cast_field<uint64_t>(v, "memory_budget", "a non-negative int");
          }},
    Field{
        "splat_budget",
        "the most Gaussians a LodSet's frame draws, each chunk at the level the camera calls for; 0: level 0",
        [](const RenderSettings& s) { return nb::cast(s.splat_budget); },
        [](RenderSettings& s, nb::handle v) {
          s.splat_budget = cast_field<uint64_t>(v, "splat_budget", "a non-negative int");
        }},
    Field{"region",
          "(x, y, width, height): render only those pixels, each the whole frame's to the bit, into an image "
          "of that size; None: the whole image",
          [](const RenderSettings& s) {
            if (s.region.whole()) return nb::object(nb::none());
            return nb::object(nb::make_tuple(s.region.x, s.region.y, s.region.width, s.region.height));
          },
          [](RenderSettings& s, nb::handle v) {
            if (v.is_none()) {
              s.region = PixelRegion{};
              return;
            }
            const auto r = cast_field<std::array<int, 4>>(v, "region", "(x, y, width, height) or None");
            s.region = PixelRegion{r[0], r[1], r[2], r[3]};
          }},
};

const Field* find_field(const std::string& name) {
  for (const Field& field : kFields)
    if (name == field.name) return &field;
  return nullptr;
}

// Sets each of `overrides` on `settings`; TypeError for a name that is no field, as Python raises it for
// an unexpected keyword argument of `function`.
void apply(RenderSettings& settings, const nb::kwargs& overrides, const char* function) {
  for (const auto& [key, value] : overrides) {
    const std::string name = nb::cast<std::string>(key);
    const Field* field = find_field(name);
    if (!field) {
      const std::string message =
          std::string(function) + " got an unexpected keyword argument '" + name + "'";
      throw nb::type_error(message.c_str());
    }
    field->set(settings, value);
  }
}

}  // namespace

RenderSettings settings_with(const RenderSettings* base, const nb::kwargs& overrides, const char* function) {
  RenderSettings settings = base ? *base : RenderSettings{};
  apply(settings, overrides, function);
  return settings;
}

void bind_settings(nb::module_& m) {
  auto settings_class = nb::class_<RenderSettings>(
      m, "RenderSettings",
      "Everything that changes how one frame is rendered: the C++ RenderSettings "
      "(tilesplat/render_settings.h) "
      "with its defaults, its fields by the names of Renderer.render()'s keywords. "
      "RenderSettings(**fields) sets some; settings.replace(**fields) is a changed copy; "
      "Renderer.render(camera, settings, **fields) and render_reference take one, the keywords overriding "
      "its fields. A field is checked when it is set (ValueError for a bad value, TypeError for a wrong "
      "type); what the frame as a whole must satisfy is checked when it renders.");
  settings_class
      .def(
          "__init__",
          [](RenderSettings* self, const nb::kwargs& fields) {
            new (self) RenderSettings();
            apply(*self, fields, "RenderSettings()");
          },
          "Every field at its default, but those given.")
      .def(
          "replace",
          [](const RenderSettings& settings, const nb::kwargs& fields) {
            RenderSettings changed = settings;
            apply(changed, fields, "RenderSettings.replace()");
            return changed;
          },
          "A copy with the fields given changed.")
      .def("__eq__", [](const RenderSettings& a, const RenderSettings& b) { return a == b; })
      .def("__repr__", [](const RenderSettings& settings) {
        // The fields that differ from the defaults, as the constructor takes them.
        const RenderSettings defaults;
        std::string text = "RenderSettings(";
        bool first = true;
        for (const Field& field : kFields) {
          const nb::str value = nb::repr(field.get(settings));
          if (std::string(value.c_str()) == nb::repr(field.get(defaults)).c_str()) continue;
          text += std::string(first ? "" : ", ") + field.name + "=" + value.c_str();
          first = false;
        }
        return text + ")";
      });
  nb::list names;
  for (const Field& field : kFields) {
    names.append(field.name);
    // Each field a property whose getter and setter hold the field's index in the table, so that the
    // table stays the one description of the field.
    const size_t index = size_t(&field - kFields.data());
    settings_class.def_prop_rw(
        field.name, [index](const RenderSettings& s) { return kFields[index].get(s); },
        [index](RenderSettings& s, nb::handle value) { kFields[index].set(s, value); }, field.doc);
  }
  settings_class.attr("fields") = nb::tuple(names);
}

}  // namespace tilesplat::python
