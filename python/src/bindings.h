// tilesplat._core's pieces: one binding function per area of the engine's public API, and the helpers
// they share (numpy views, argument checks). module.cpp calls the binding functions in order.
#pragma once
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/image.h"
#include "tilesplat/renderer.h"

namespace tilesplat::python {

namespace nb = nanobind;

void bind_scenes(
    nb::module_& m);  // scene_bindings.cpp: Scene, load_scene, SceneInstances, SceneInParts, LodSet
void bind_cameras(nb::module_& m);   // camera_bindings.cpp: Camera, CameraView, camera sets, orbits, paths
void bind_effects(nb::module_& m);   // effect_bindings.cpp: ThinLens, Shutter and their sample functions
void bind_images(nb::module_& m);    // image_bindings.cpp: Image, read_exr, compare_images
void bind_settings(nb::module_& m);  // settings_bindings.cpp: RenderSettings
void bind_renderer(nb::module_& m);  // renderer_bindings.cpp: devices, Renderer, render_reference

// The Python Renderer: the engine's renderer, which is neither copyable nor movable, behind a pointer.
struct RendererHandle {
  std::unique_ptr<Renderer> renderer;
};
// gradient_bindings.cpp: Renderer.backward, reference_backward, NotDifferentiable (bind_renderer calls it).
void bind_gradients(nb::module_& m, nb::class_<RendererHandle>& renderer);

template <typename T>
using NumpyArray = nb::ndarray<nb::numpy, T>;

// A numpy view of `values` with the given shape, kept alive by `owner` (the Python object that holds
// the vector).
template <typename T>
NumpyArray<T> view_of(std::vector<T>& values, std::initializer_list<size_t> shape, nb::handle owner) {
  return NumpyArray<T>(values.data(), shape, owner);
}

// A numpy array that owns `values` (moved to the heap, freed with the array), with the given shape.
template <typename T>
NumpyArray<T> owned_array(std::vector<T>&& values, std::initializer_list<size_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  nb::capsule owner(owned, [](void* pointer) noexcept { delete static_cast<std::vector<T>*>(pointer); });
  return NumpyArray<T>(owned->data(), shape, owner);
}

// A C-contiguous float32 array on the CPU; other dtypes and layouts are converted (copied) on the way in.
using FloatInput = nb::ndarray<const float, nb::c_contig, nb::device::cpu>;

// The values of `array`, which must have the shape given (-1: any size on that axis), all finite; else
// std::invalid_argument naming `name`, the shapes or the first non-finite value.
std::vector<float> finite_values(const FloatInput& array, const char* name,
                                 std::initializer_list<int64_t> shape);

// The enumerator of `choices` whose to_string is `text`; else std::invalid_argument
// "NAME must be one of A, B, C, got 'TEXT'".
template <typename Enum, size_t N>
Enum parse_choice(const std::string& name, const std::string& text, const std::array<Enum, N>& choices) {
  std::string allowed;
  for (const Enum choice : choices) {
    if (to_string(choice) == text) return choice;
    allowed += (allowed.empty() ? "" : ", ") + to_string(choice);
  }
  throw std::invalid_argument(name + " must be one of " + allowed + ", got '" + text + "'");
}

// Raises FileNotFoundError naming the file, as open() would, before the engine reads it.
void check_exists(const std::filesystem::path& path, const char* what);

// SaturatedValues as {channel: count}.
nb::dict saturated_dict(const SaturatedValues& saturated);

}  // namespace tilesplat::python
