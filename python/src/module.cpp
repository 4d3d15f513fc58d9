// tilesplat._core: the engine's public API for Python, numpy arrays in and out (nanobind).
//
// Scenes, cameras, the renderer and its images are the C++ types with thin wrappers, bound by area in
// the *_bindings.cpp files beside this one (bindings.h): a scene's arrays and an image's channels are
// numpy views of the C++ vectors, kept alive by the Python object that owns them; render() releases the
// GIL while the frame runs. C++ exceptions reach Python with their messages: SceneError as
// tilesplat.SceneError (a ValueError), std::invalid_argument as ValueError, a missing file as
// FileNotFoundError, anything else as RuntimeError.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "bindings.h"
#include "tilesplat/scene.h"
#include "tilesplat/version.h"

namespace tilesplat::python {

std::vector<float> finite_values(const FloatInput& array, const char* name,
                                 std::initializer_list<int64_t> shape) {
  std::string expected = "(";
  for (auto it = shape.begin(); it != shape.end(); ++it)
    expected += (it == shape.begin() ? "" : ", ") + (*it < 0 ? std::string("N") : std::to_string(*it));
  expected += shape.size() == 1 ? ",)" : ")";
  bool matches = array.ndim() == shape.size();
  size_t axis = 0;
  for (const int64_t size : shape) {
    if (matches && size >= 0 && array.shape(axis) != size_t(size)) matches = false;
    ++axis;
  }
  if (!matches) {
    std::string got = "(";
    for (size_t a = 0; a < array.ndim(); ++a) got += (a ? ", " : "") + std::to_string(array.shape(a));
    got += array.ndim() == 1 ? ",)" : ")";
    throw std::invalid_argument(std::string(name) + " must have the shape " + expected + ", got " + got);
  }
  std::vector<float> values(array.data(), array.data() + array.size());
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw std::invalid_argument(std::string(name) + " holds a non-finite value (" +
                                  std::to_string(values[i]) + ") at flat index " + std::to_string(i));
  return values;
}

void check_exists(const std::filesystem::path& path, const char* what) {
  std::error_code error;
  if (std::filesystem::exists(path, error)) return;
  const std::string message = std::string("cannot read ") + what + " '" + path.string() + "': no such file";
  PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
  throw nb::python_error();
}

nb::dict saturated_dict(const SaturatedValues& saturated) {
  nb::dict out;
  for (const auto& [channel, count] : saturated.channels) out[channel.c_str()] = count;
  return out;
}

}  // namespace tilesplat::python

NB_MODULE(_core, m) {
  namespace python = tilesplat::python;
  m.attr("__version__") = tilesplat::build_info().version;
  nanobind::exception<tilesplat::SceneError>(m, "SceneError", PyExc_ValueError);
  python::bind_scenes(m);
  python::bind_cameras(m);
  python::bind_effects(m);
  python::bind_images(m);
  python::bind_settings(m);
  python::bind_renderer(m);
}
