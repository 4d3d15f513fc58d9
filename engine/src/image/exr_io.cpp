// OpenEXR files of RenderImages: R G B A, optional Z (depth) and "splats" (per-pixel splat counts).
#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfChromaticities.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfPixelType.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfTestFile.h>
#include <ImfVecAttribute.h>
#include <half.h>

#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "image/atomic_file.h"
#include "image/saturate.h"
#include "tilesplat/image.h"
#include "tilesplat/version.h"

namespace tilesplat {
namespace {

constexpr std::array<const char*, 4> kColourChannels = {"R", "G", "B", "A"};
constexpr const char* kDepthChannel = "Z";
constexpr const char* kSplatCountChannel = "splats";
constexpr const char* kColourInteropAttribute = "colorInteropID";

// The encoding a header names for its R G B; a file without the attribute holds display values (those
// tilesplat wrote before it recorded one, and the float64 references).
ColourEncoding stored_encoding(const Imf::Header& header) {
  const auto* id = header.findTypedAttribute<Imf::StringAttribute>(kColourInteropAttribute);
  if (!id) return ColourEncoding::kSrgbDisplay;
  for (const ColourEncoding encoding : {ColourEncoding::kSceneLinear, ColourEncoding::kSrgbDisplay})
    if (id->value() == to_string(encoding)) return encoding;
  throw std::runtime_error(std::string(kColourInteropAttribute) + " '" + id->value() +
                           "' is not an encoding tilesplat reads (lin_rec709_scene, srgb_rec709_display)");
}

void check_writable_image(const std::filesystem::path& path, const RenderImage& image) {
  const std::string prefix = "cannot write " + path.string() + ": ";
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(prefix + "image size " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " is empty");
  const size_t pixels = image.pixels();
  const std::string size_text = std::to_string(image.width) + "x" + std::to_string(image.height);
  if (image.rgba.size() != 4 * pixels)
    throw std::runtime_error(prefix + "rgba holds " + std::to_string(image.rgba.size()) +
                             " values, a " + size_text + " image needs " + std::to_string(4 * pixels));
  if (!image.depth.empty() && image.depth.size() != pixels)
    throw std::runtime_error(prefix + "depth holds " + std::to_string(image.depth.size()) +
                             " values, a " + size_text + " image needs " + std::to_string(pixels) +
                             " (or none)");
  if (!image.splat_count.empty() && image.splat_count.size() != pixels)
    throw std::runtime_error(prefix + "splat_count holds " + std::to_string(image.splat_count.size()) +
                             " values, a " + size_text + " image needs " + std::to_string(pixels) +
                             " (or none)");
}

// The attributes write_exr sets itself, which options.attributes may not replace: OpenEXR would
// overwrite them with strings and write a file no reader opens.
bool is_written_by_the_writer(const std::string& name) {
  static const std::array<const char*, 15> kOwn = {
      "channels",         "compression",        "dataWindow",        "displayWindow", "lineOrder",
      "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "tiles",         "type",
      "version",          "chromaticities",     "worldToCamera",     "worldToNDC",    "colorInteropID"};
  for (const char* own : kOwn)
    if (name == own) return true;
  return name.rfind("tilesplat", 0) == 0;
}

void check_attributes(const std::filesystem::path& path, const RenderImage& image,
                      const ExrWriteOptions& options) {
  const PixelRegion& region = options.region;
  if (!region.whole()) {
    const std::string where = "cannot write " + path.string() + ": the image's region " + to_string(region);
    if (region.width != image.width || region.height != image.height)
      throw std::runtime_error(where + " is not the image's size, " + std::to_string(image.width) + "x" +
                               std::to_string(image.height));
    try {
      validate(region, options.display_width, options.display_height);
    } catch (const std::invalid_argument&) {
      throw std::runtime_error(where + " does not lie within the " + std::to_string(options.display_width) +
                               "x" + std::to_string(options.display_height) + " display window");
    }
  }
  for (const auto& [name, value] : options.attributes) {
    if (name.empty())
      throw std::runtime_error("cannot write " + path.string() + ": an attribute has an empty name");
    if (is_written_by_the_writer(name))
      throw std::runtime_error(
          "cannot write " + path.string() + ": attribute '" + name +
          "' is set by the writer itself (names starting with 'tilesplat' are reserved)");
  }
}

// The camera in OpenEXR's standard attributes (documented at read_exr_camera) and exactly in tilesplat's.
void add_camera_attributes(Imf::Header& header, const Camera& camera) {
  // OpenEXR's camera space is tilesplat's with y negated (up instead of down). Imath multiplies row
  // vectors, p * M, so M holds the camera axes as columns and the translation as its last row.
  const double flip[3] = {1, -1, 1};
  Imath::M44d world_to_camera;  // identity
  for (int axis = 0; axis < 3; ++axis) {
    double translation = 0;
    for (int k = 0; k < 3; ++k) {
      const double r = flip[axis] * camera.rotation[size_t(axis) * 3 + size_t(k)];
      world_to_camera[k][axis] = r;
      translation -= r * camera.position[size_t(k)];
    }
    world_to_camera[3][axis] = translation;
  }
  // OpenEXR camera space (x, y up, z) to NDC: x = (fx x + cx z) / (width z), y = (-fy y + cy z) / (height z),
  // z = 1 / z, from homogeneous w = z.
  const double w = camera.width, h = camera.height;
  const Imath::M44d camera_to_ndc(camera.fx / w, 0, 0, 0,   //
                                  0, -camera.fy / h, 0, 0,  //
                                  camera.cx / w, camera.cy / h, 0, 1, 0, 0, 1, 0);
  const Imath::M44d world_to_ndc = world_to_camera * camera_to_ndc;
  Imf::addWorldToCamera(header, Imath::M44f(world_to_camera));
  // worldToNDC is a pinhole's matrix: other models' pixels are not a matrix of the point.
  if (camera.model == CameraModel::kPinhole) Imf::addWorldToNDC(header, Imath::M44f(world_to_ndc));

  Imath::M33d rotation;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rotation[r][c] = camera.rotation[size_t(r) * 3 + size_t(c)];
  header.insert("tilesplatRotation", Imf::M33dAttribute(rotation));
  header.insert("tilesplatPosition",
                Imf::V3dAttribute(Imath::V3d(camera.position[0], camera.position[1], camera.position[2])));
  header.insert("tilesplatFocalLength", Imf::V2dAttribute(Imath::V2d(camera.fx, camera.fy)));
  header.insert("tilesplatPrincipalPoint", Imf::V2dAttribute(Imath::V2d(camera.cx, camera.cy)));
  if (camera.model != CameraModel::kPinhole) {  // a pinhole's header stays as it always was
    header.insert("tilesplatCameraModel", Imf::StringAttribute(camera_model_name(camera.model)));
    std::string coefficients;
    for (const double k : camera.distortion) {
      char text[32];
      std::snprintf(text, sizeof(text), "%.17g", k);
      if (!coefficients.empty()) coefficients += ' ';
      coefficients += text;
    }
    header.insert("tilesplatDistortion", Imf::StringAttribute(coefficients));
  }
}

// tilesplatCameraModel and tilesplatDistortion (add_camera_attributes) into `camera`; absent: the pinhole.
void read_camera_model(const Imf::Header& header, Camera& camera) {
  const auto* model = header.findTypedAttribute<Imf::StringAttribute>("tilesplatCameraModel");
  const auto* distortion = header.findTypedAttribute<Imf::StringAttribute>("tilesplatDistortion");
  if (model == nullptr && distortion == nullptr) return;
  if (model == nullptr || distortion == nullptr)
    throw std::runtime_error(
        "tilesplatCameraModel and tilesplatDistortion come together, and one is missing");
  try {
    camera.model = parse_camera_model(model->value());
  } catch (const std::invalid_argument& error) {
    throw std::runtime_error(std::string("tilesplatCameraModel: ") + error.what());
  }
  std::istringstream words(distortion->value());
  for (double& k : camera.distortion)
    if (!(words >> k))
      throw std::runtime_error("tilesplatDistortion must hold 8 numbers, got '" + distortion->value() + "'");
  std::string extra;
  if (words >> extra) throw std::runtime_error("tilesplatDistortion holds more than 8 numbers");
}

Imf::Compression openexr_compression(ExrCompression compression) {
  switch (compression) {
    case ExrCompression::kZip:
      return Imf::ZIP_COMPRESSION;
    case ExrCompression::kPiz:
      return Imf::PIZ_COMPRESSION;
    case ExrCompression::kDwaa:
      return Imf::DWAA_COMPRESSION;
    case ExrCompression::kNone:
      return Imf::NO_COMPRESSION;
  }
  throw std::invalid_argument("unknown ExrCompression " + std::to_string(int(compression)));
}

// The provenance every file carries, then the caller's attributes.
void add_string_attributes(Imf::Header& header, const ExrWriteOptions& options) {
  const BuildInfo build = build_info();
  header.insert("tilesplatVersion", Imf::StringAttribute(build.version));
  if (*build.git_commit) header.insert("tilesplatCommit", Imf::StringAttribute(build.git_commit));
  if (*build.build_type) header.insert("tilesplatBuildType", Imf::StringAttribute(build.build_type));
  for (const auto& [name, value] : options.attributes) header.insert(name, Imf::StringAttribute(value));
}

// A float stored as OpenEXR's half: past +-65504 (HALF_MAX; half rounds 65520 and above to an infinity)
// the largest finite half with the value's sign, counted in `saturated` (image/saturate.h's rule).
Imath::half saturate_to_half(float value, uint64_t& saturated) {
  constexpr float kMax = 65504.0f;
  if (std::abs(value) > kMax) {
    ++saturated;
    return Imath::half(std::copysign(kMax, value));
  }
  return Imath::half(value);
}

// kSaturatedAttribute's value: "R 23747 G 23747 B 23747 (half)".
std::string saturation_record(const SaturatedValues& saturated, bool half) {
  std::string record;
  for (const auto& [name, count] : saturated.channels) {
    if (count == 0) continue;
    record += name + " " + std::to_string(count) + " ";
  }
  return record + (half ? "(half)" : "(float)");
}

std::string channel_names(const Imf::ChannelList& channels) {
  std::string names;
  for (auto channel = channels.begin(); channel != channels.end(); ++channel) {
    if (!names.empty()) names += ' ';
    names += channel.name();
  }
  return names.empty() ? "none" : names;
}

// Throws plain std::runtime_errors (and OpenEXR's exceptions); read_exr adds the file name.
// The caller (with_exr_file_named_in_errors) has checked that the file is OpenEXR.
StoredExr read_exr_file(const std::filesystem::path& path) {
  Imf::InputFile file(path.c_str());
  const Imf::Header& header = file.header();
  const ColourEncoding encoding = stored_encoding(header);
  const Imath::Box2i data_window = header.dataWindow();
  const std::int64_t width = std::int64_t{data_window.max.x} - data_window.min.x + 1;
  const std::int64_t height = std::int64_t{data_window.max.y} - data_window.min.y + 1;
  if (width <= 0 || height <= 0 || width > INT_MAX || height > INT_MAX)
    throw std::runtime_error("invalid data window of " + std::to_string(width) + "x" +
                             std::to_string(height) + " pixels");

  const Imf::ChannelList& channels = header.channels();
  const auto require_full_resolution = [&](const char* name) {
    const Imf::Channel* channel = channels.findChannel(name);
    if (channel && (channel->xSampling != 1 || channel->ySampling != 1))
      throw std::runtime_error(std::string("channel ") + name + " is subsampled, which is not supported");
    return channel != nullptr;
  };
  for (const char* name : {"R", "G", "B"})
    if (!require_full_resolution(name))
      throw std::runtime_error(std::string("no ") + name + " channel (channels: " + channel_names(channels) +
                               ")");
  require_full_resolution("A");
  const bool has_depth = require_full_resolution(kDepthChannel);
  const bool has_splat_counts = require_full_resolution(kSplatCountChannel);

  RenderImage image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  const size_t pixels = image.pixels();
  image.rgba.resize(4 * pixels);

  // Slice::Make offsets the base pointer by the data window's origin, so a window that does not
  // start at (0, 0) still lands at the start of our buffers. OpenEXR converts any stored pixel
  // type to the slice's type.
  Imf::FrameBuffer frame;
  const size_t rgba_pixel_bytes = 4 * sizeof(float);
  for (size_t c = 0; c < kColourChannels.size(); ++c) {
    // A missing A channel is filled with fillValue: such an image is fully opaque.
    frame.insert(kColourChannels[c],
                 Imf::Slice::Make(Imf::FLOAT, &image.rgba[c], data_window, rgba_pixel_bytes,
                                  rgba_pixel_bytes * image.width, 1, 1, /*fillValue=*/1.0));
  }
  if (has_depth) {
    image.depth.resize(pixels);
    frame.insert(kDepthChannel, Imf::Slice::Make(Imf::FLOAT, image.depth.data(), data_window));
  }
  if (has_splat_counts) {
    image.splat_count.resize(pixels);
    frame.insert(kSplatCountChannel, Imf::Slice::Make(Imf::UINT, image.splat_count.data(), data_window));
  }

  if (!file.isComplete()) throw std::runtime_error("the file is incomplete (truncated?)");
  file.setFrameBuffer(frame);
  file.readPixels(data_window.min.y, data_window.max.y);
  return {std::move(image), encoding};
}

// Runs read(), a reader of the EXR file `path`, once the file exists and is OpenEXR, with the file
// named in every error: OpenEXR's messages (Iex::BaseExc derives from std::exception) rarely name it.
template <typename Read>
auto with_exr_file_named_in_errors(const std::filesystem::path& path, const Read& read) {
  const std::string prefix = "cannot read " + path.string() + ": ";
  std::error_code status_error;
  const auto status = std::filesystem::status(path, status_error);
  if (!std::filesystem::exists(status)) throw std::runtime_error(prefix + "the file does not exist");
  if (std::filesystem::is_directory(status)) throw std::runtime_error(prefix + "it is a directory");
  try {
    // isOpenExrFile gives a meaningful message for a file that is not EXR at all, where the
    // InputFile constructor would report something about its internals.
    if (!Imf::isOpenExrFile(path.c_str())) throw std::runtime_error("not an OpenEXR file");
    return read();
  } catch (const std::exception& error) {
    std::throw_with_nested(std::runtime_error(prefix + error.what()));
  }
}

}  // namespace

SaturatedValues write_exr(const std::filesystem::path& path, const RenderImage& image,
                          const ExrWriteOptions& options) {
  check_writable_image(path, image);
  check_attributes(path, image, options);

  // What the file holds where the options change the image: the colours in the encoding asked for
  // (a file without A, or with A = 1, is opaque, so its colours convert as they are), A = 1 for an
  // opaque frame, and the far value in Z where nothing was blended. A decoded colour past float's range
  // saturates (convert_colours), counted.
  SaturatedValues saturated;
  const bool opaque = options.opaque_alpha || !options.alpha;
  const std::vector<float>* rgba = &image.rgba;
  std::vector<float> stored_rgba;
  if (opaque || options.colour != ColourEncoding::kSrgbDisplay) {
    stored_rgba = convert_colours(image.rgba, ColourEncoding::kSrgbDisplay, options.colour, opaque, &saturated);
    if (options.opaque_alpha)
      for (size_t i = 3; i < stored_rgba.size(); i += 4) stored_rgba[i] = 1.0f;
    rgba = &stored_rgba;
  }
  const std::vector<float>* depth = &image.depth;
  std::vector<float> depth_with_empty;
  if (options.empty_depth != 0 && !image.depth.empty()) {
    depth_with_empty = image.depth;
    for (size_t i = 0; i < depth_with_empty.size(); ++i)
      if (image.rgba[4 * i + 3] == 0.0f) depth_with_empty[i] = options.empty_depth;
    depth = &depth_with_empty;
  }

  // Half colours: a value past half's range (a display value above about 113 decodes past 65,504 of
  // linear light) is stored as the largest finite half, counted per channel, never as an infinity.
  const Imf::PixelType colour_type = options.half ? Imf::HALF : Imf::FLOAT;
  std::vector<Imath::half> rgba_half;
  if (options.half) {
    rgba_half.reserve(rgba->size());
    std::array<uint64_t, 4> past_half{};
    for (size_t i = 0; i < rgba->size(); ++i)
      rgba_half.push_back(saturate_to_half((*rgba)[i], past_half[i % 4]));
    // Every colour that saturated as a float saturates as a half too: the half counts replace them.
    saturated = {};
    for (size_t c = 0; c < kColourChannels.size(); ++c)
      if (past_half[c] > 0 && (c < 3 || options.alpha)) saturated.channels[kColourChannels[c]] = past_half[c];
  }
  const char* colour_data = options.half ? reinterpret_cast<const char*>(rgba_half.data())
                                         : reinterpret_cast<const char*>(rgba->data());
  const size_t colour_value_bytes = options.half ? sizeof(Imath::half) : sizeof(float);

  detail::write_file_atomically(path, [&](const std::filesystem::path& temp) {
    // A region's pixels as the data window inside the whole image's display window.
    const PixelRegion& region = options.region;
    Imf::Header header =
        region.whole()
            ? Imf::Header(image.width, image.height)
            : Imf::Header(Imath::Box2i({0, 0}, {options.display_width - 1, options.display_height - 1}),
                          Imath::Box2i({region.x, region.y},
                                       {region.x + region.width - 1, region.y + region.height - 1}));
    header.compression() = openexr_compression(options.compression);
    add_string_attributes(header, options);
    Imf::addChromaticities(header, Imf::Chromaticities());  // Rec. 709 primaries, D65 white
    // The transfer function beside the primaries, by the Color Interop Forum's identifier.
    header.insert(kColourInteropAttribute, Imf::StringAttribute(to_string(options.colour)));
    if (options.camera) add_camera_attributes(header, *options.camera);
    if (saturated.total() > 0)
      header.insert(kSaturatedAttribute, Imf::StringAttribute(saturation_record(saturated, options.half)));
    const Imath::Box2i data_window = header.dataWindow();

    Imf::FrameBuffer frame;
    const size_t colour_pixel_bytes = 4 * colour_value_bytes;
    for (size_t c = 0; c < kColourChannels.size(); ++c) {
      if (c == 3 && !options.alpha) continue;
      header.channels().insert(kColourChannels[c], Imf::Channel(colour_type));
      frame.insert(kColourChannels[c],
                   Imf::Slice::Make(colour_type, colour_data + c * colour_value_bytes, data_window,
                                    colour_pixel_bytes, colour_pixel_bytes * image.width));
    }
    // Depth stays FLOAT in half mode: half's 11-bit significand cannot tell apart depths a few
    // centimetres apart at tens of metres.
    if (!image.depth.empty()) {
      header.channels().insert(kDepthChannel, Imf::Channel(Imf::FLOAT));
      frame.insert(kDepthChannel, Imf::Slice::Make(Imf::FLOAT, depth->data(), data_window));
    }
    // Counts as FLOAT: OpenImageIO (and the compositors on it) read a UINT channel as a normalised
    // value, which shows every count as about 0. Floats hold every count up to 2^24 exactly.
    const std::vector<float> splat_counts(image.splat_count.begin(), image.splat_count.end());
    if (!image.splat_count.empty()) {
      header.channels().insert(kSplatCountChannel, Imf::Channel(Imf::FLOAT));
      frame.insert(kSplatCountChannel, Imf::Slice::Make(Imf::FLOAT, splat_counts.data(), data_window));
    }

    // Scoped so the file is complete and closed before write_file_atomically renames it.
    Imf::OutputFile file(temp.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);  // the data window's rows
  });
  return saturated;
}

StoredExr read_exr_as_stored(const std::filesystem::path& path) {
  return with_exr_file_named_in_errors(path, [&] { return read_exr_file(path); });
}

RenderImage read_exr(const std::filesystem::path& path) {
  StoredExr stored = read_exr_as_stored(path);
  if (stored.encoding != ColourEncoding::kSrgbDisplay)  // display values (and unmarked files) as they are
    stored.image.rgba = convert_colours(stored.image.rgba, stored.encoding, ColourEncoding::kSrgbDisplay);
  return std::move(stored.image);
}

std::string to_string(ExrCompression compression) {
  switch (compression) {
    case ExrCompression::kZip:
      return "zip";
    case ExrCompression::kPiz:
      return "piz";
    case ExrCompression::kDwaa:
      return "dwaa";
    case ExrCompression::kNone:
      return "none";
  }
  return "unknown";
}

std::optional<Camera> read_exr_camera(const std::filesystem::path& path) {
  return with_exr_file_named_in_errors(path, [&]() -> std::optional<Camera> {
    const Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const auto* rotation = header.findTypedAttribute<Imf::M33dAttribute>("tilesplatRotation");
    const auto* position = header.findTypedAttribute<Imf::V3dAttribute>("tilesplatPosition");
    const auto* focal = header.findTypedAttribute<Imf::V2dAttribute>("tilesplatFocalLength");
    const auto* principal = header.findTypedAttribute<Imf::V2dAttribute>("tilesplatPrincipalPoint");
    const int present =
        (rotation != nullptr) + (position != nullptr) + (focal != nullptr) + (principal != nullptr);
    if (present == 0) return std::nullopt;
    if (present != 4)
      throw std::runtime_error(
          "the camera attributes are incomplete (tilesplatRotation, tilesplatPosition, "
          "tilesplatFocalLength and tilesplatPrincipalPoint, of types m33d, v3d, v2d, v2d)");
    Camera camera;
    const Imath::Box2i window = header.dataWindow();
    camera.width = window.max.x - window.min.x + 1;
    camera.height = window.max.y - window.min.y + 1;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) camera.rotation[size_t(r) * 3 + size_t(c)] = rotation->value()[r][c];
    for (int i = 0; i < 3; ++i) camera.position[size_t(i)] = position->value()[i];
    camera.fx = focal->value().x;
    camera.fy = focal->value().y;
    camera.cx = principal->value().x;
    camera.cy = principal->value().y;
    read_camera_model(header, camera);
    try {
      validate(camera);
    } catch (const std::invalid_argument& error) {
      throw std::runtime_error(std::string("its camera attributes describe an ") + error.what());
    }
    return camera;
  });
}

std::map<std::string, std::string> read_exr_string_attributes(const std::filesystem::path& path) {
  return with_exr_file_named_in_errors(path, [&] {
    const Imf::InputFile file(path.c_str());
    std::map<std::string, std::string> attributes;
    for (auto attribute = file.header().begin(); attribute != file.header().end(); ++attribute)
      if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&attribute.attribute()))
        attributes.emplace(attribute.name(), text->value());
    return attributes;
  });
}

}  // namespace tilesplat
