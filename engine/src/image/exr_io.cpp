// OpenEXR files of RenderImages: R G B A, optional Z (depth) and "splats" (per-pixel splat counts).
#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPixelType.h>
#include <ImfStringAttribute.h>
#include <ImfTestFile.h>
#include <half.h>

#include <array>
#include <climits>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "image/atomic_file.h"
#include "tilesplat/image.h"
#include "tilesplat/version.h"

namespace tilesplat {
namespace {

constexpr std::array<const char*, 4> kColourChannels = {"R", "G", "B", "A"};
constexpr const char* kDepthChannel = "Z";
constexpr const char* kSplatCountChannel = "splats";

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
  static const std::array<const char*, 11> kOwn = {
      "channels",         "compression",        "dataWindow",        "displayWindow", "lineOrder",
      "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "tiles",         "type",
      "version"};
  for (const char* own : kOwn)
    if (name == own) return true;
  return name.rfind("tilesplat", 0) == 0;
}

void check_attributes(const std::filesystem::path& path, const ExrWriteOptions& options) {
  for (const auto& [name, value] : options.attributes) {
    if (name.empty())
      throw std::runtime_error("cannot write " + path.string() + ": an attribute has an empty name");
    if (is_written_by_the_writer(name))
      throw std::runtime_error(
          "cannot write " + path.string() + ": attribute '" + name +
          "' is set by the writer itself (names starting with 'tilesplat' are reserved)");
  }
}

// The provenance every file carries, then the caller's attributes.
void add_string_attributes(Imf::Header& header, const ExrWriteOptions& options) {
  const BuildInfo build = build_info();
  header.insert("tilesplatVersion", Imf::StringAttribute(build.version));
  if (*build.git_commit) header.insert("tilesplatCommit", Imf::StringAttribute(build.git_commit));
  if (*build.build_type) header.insert("tilesplatBuildType", Imf::StringAttribute(build.build_type));
  for (const auto& [name, value] : options.attributes) header.insert(name, Imf::StringAttribute(value));
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
RenderImage read_exr_file(const std::filesystem::path& path) {
  // isOpenExrFile gives a meaningful message for a file that is not EXR at all, where the
  // InputFile constructor would report something about its internals.
  if (!Imf::isOpenExrFile(path.c_str())) throw std::runtime_error("not an OpenEXR file");

  Imf::InputFile file(path.c_str());
  const Imf::Header& header = file.header();
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
  return image;
}

// Runs read(), a reader of `path`, with the file named in every error: OpenEXR's messages
// (Iex::BaseExc derives from std::exception) rarely name it.
template <typename Read>
auto with_file_named_in_errors(const std::filesystem::path& path, const Read& read) {
  const std::string prefix = "cannot read " + path.string() + ": ";
  std::error_code status_error;
  const auto status = std::filesystem::status(path, status_error);
  if (!std::filesystem::exists(status)) throw std::runtime_error(prefix + "the file does not exist");
  if (std::filesystem::is_directory(status)) throw std::runtime_error(prefix + "it is a directory");
  try {
    return read();
  } catch (const std::exception& error) {
    std::throw_with_nested(std::runtime_error(prefix + error.what()));
  }
}

}  // namespace

void write_exr(const std::filesystem::path& path, const RenderImage& image, const ExrWriteOptions& options) {
  check_writable_image(path, image);
  check_attributes(path, options);

  const Imf::PixelType colour_type = options.half ? Imf::HALF : Imf::FLOAT;
  std::vector<Imath::half> rgba_half;
  if (options.half) {
    rgba_half.reserve(image.rgba.size());
    for (const float value : image.rgba) rgba_half.emplace_back(value);
  }
  const char* colour_data =
      options.half ? reinterpret_cast<const char*>(rgba_half.data())
                   : reinterpret_cast<const char*>(image.rgba.data());
  const size_t colour_value_bytes = options.half ? sizeof(Imath::half) : sizeof(float);

  detail::write_file_atomically(path, [&](const std::filesystem::path& temp) {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    add_string_attributes(header, options);
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
      frame.insert(kDepthChannel, Imf::Slice::Make(Imf::FLOAT, image.depth.data(), data_window));
    }
    if (!image.splat_count.empty()) {
      header.channels().insert(kSplatCountChannel, Imf::Channel(Imf::UINT));
      frame.insert(kSplatCountChannel, Imf::Slice::Make(Imf::UINT, image.splat_count.data(), data_window));
    }

    // Scoped so the file is complete and closed before write_file_atomically renames it.
    Imf::OutputFile file(temp.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  });
}

RenderImage read_exr(const std::filesystem::path& path) {
  return with_file_named_in_errors(path, [&] { return read_exr_file(path); });
}

std::map<std::string, std::string> read_exr_string_attributes(const std::filesystem::path& path) {
  return with_file_named_in_errors(path, [&] {
    if (!Imf::isOpenExrFile(path.c_str())) throw std::runtime_error("not an OpenEXR file");
    const Imf::InputFile file(path.c_str());
    std::map<std::string, std::string> attributes;
    for (auto attribute = file.header().begin(); attribute != file.header().end(); ++attribute)
      if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&attribute.attribute()))
        attributes.emplace(attribute.name(), text->value());
    return attributes;
  });
}

}  // namespace tilesplat
