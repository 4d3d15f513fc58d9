// Images for Python: tilesplat.Image (its channels as numpy views), the EXR and PNG it writes, and the
// comparison of two images.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>

#include "bindings.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"

namespace tilesplat::python {

using namespace nb::literals;

void bind_images(nb::module_& m) {
  nb::class_<RenderImage>(
      m, "Image",
      "A rendered frame: rgba (H, W, 4) premultiplied over the background, in the trained "
      "display values (sRGB-encoded, as the photographs were: docs/colour.md), depth (H, W) "
      "expected view depth, splat_count (H, W) blended splats; numpy views of the image.")
      .def_ro("width", &RenderImage::width)
      .def_ro("height", &RenderImage::height)
      .def_prop_ro("rgba",
                   [](nb::handle self) {
                     auto& image = nb::cast<RenderImage&>(self);
                     return view_of(image.rgba, {size_t(image.height), size_t(image.width), 4}, self);
                   })
      .def_prop_ro("depth",
                   [](nb::handle self) -> std::optional<NumpyArray<float>> {
                     auto& image = nb::cast<RenderImage&>(self);
                     if (image.depth.empty()) return std::nullopt;
                     return view_of(image.depth, {size_t(image.height), size_t(image.width)}, self);
                   })
      .def_prop_ro("splat_count",
                   [](nb::handle self) -> std::optional<NumpyArray<uint32_t>> {
                     auto& image = nb::cast<RenderImage&>(self);
                     if (image.splat_count.empty()) return std::nullopt;
                     return view_of(image.splat_count, {size_t(image.height), size_t(image.width)}, self);
                   })
      .def(
          "write_exr",
          [](const RenderImage& image, const std::filesystem::path& path, bool half,
             const std::string& compression, std::optional<Camera> camera, float empty_depth) {
            ExrWriteOptions options;
            options.half = half;
            options.empty_depth = empty_depth;
            options.compression = parse_choice("compression", compression,
                                               std::array{ExrCompression::kZip, ExrCompression::kPiz,
                                                          ExrCompression::kDwaa, ExrCompression::kNone});
            options.camera = camera;
            return saturated_dict(write_exr(path, image, options));
          },
          "path"_a, "half"_a = false, "compression"_a = "zip", "camera"_a = nb::none(),
          "empty_depth"_a = kFarDepth,
          "Writes the image as tilesplat-render does: R G B A, Z and 'splats', scene-linear, atomically; Z "
          "is "
          "empty_depth where no splat was blended (default: far, behind everything, as the app writes). "
          "A finite value past the range of its channel's type (float, or half with half=True) is stored as "
          "that type's largest finite value, never as inf; returns {channel: values saturated so}, empty "
          "when none were.")
      .def(
          "write_png",
          [](const RenderImage& image, const std::filesystem::path& path, double exposure_stops,
             const std::string& tone_map) {
            PreviewOptions options;
            options.exposure_stops = exposure_stops;
            options.tone_map = parse_choice("tone_map", tone_map,
                                            std::array{ToneMap::kNone, ToneMap::kAces, ToneMap::kReinhard});
            write_png_preview(path, image, options);
          },
          "path"_a, "exposure_stops"_a = 0.0, "tone_map"_a = "none", "Writes an 8-bit sRGB preview.")
      .def(
          "preview",
          [](const RenderImage& image, double exposure_stops, const std::string& tone_map) {
            PreviewOptions options;
            options.exposure_stops = exposure_stops;
            options.tone_map = parse_choice("tone_map", tone_map,
                                            std::array{ToneMap::kNone, ToneMap::kAces, ToneMap::kReinhard});
            return owned_array(preview_pixels(image, options),
                               {size_t(image.height), size_t(image.width), 3});
          },
          "exposure_stops"_a = 0.0, "tone_map"_a = "none",
          "The PNG preview's pixels, (H, W, 3) uint8 sRGB, for showing the frame (matplotlib's imshow): "
          "rgba holds display values already, so they are shown as they are unless graded.");

  m.def(
      "read_exr",
      [](const std::filesystem::path& path) {
        check_exists(path, "EXR");
        return read_exr(path);
      },
      "path"_a, "Reads an EXR that write_exr (or tilesplat-render) wrote.");

  m.def(
      "compare_images",
      [](const RenderImage& a, const RenderImage& b) {
        const ImageDifference difference = compare_images(a, b);
        nb::dict out;
        out["psnr_db"] = difference.psnr_db;
        out["max_abs"] = difference.max_abs;
        out["max_abs_alpha"] = difference.max_abs_alpha;
        return out;
      },
      "a"_a, "b"_a, "PSNR (RGB, peak 1) and the largest differences of two images of one size.");
}

}  // namespace tilesplat::python
