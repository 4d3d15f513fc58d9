// File access and the post-processing step shared by every scene reader (see scene_reading.h).
#include "scene/scene_reading.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "scene/rad_file.h"
#include "scene/scene_readers.h"

#if __has_include(<sys/mman.h>) && __has_include(<unistd.h>)
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#define TILESPLAT_HAS_MMAP 1
#else
#define TILESPLAT_HAS_MMAP 0
#endif

namespace tilesplat::detail {

FileContents::~FileContents() {
#if TILESPLAT_HAS_MMAP
  if (mapping_) munmap(mapping_, size_);
#endif
}

std::string FileContents::open(const std::filesystem::path& path) {
#if TILESPLAT_HAS_MMAP
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::string("cannot open: ") + std::strerror(errno);
  struct stat info {};
  if (fstat(fd, &info) != 0) {
    const std::string error = std::string("cannot open: ") + std::strerror(errno);
    ::close(fd);
    return error;
  }
  size_ = static_cast<size_t>(info.st_size);
  if (size_ > 0) {
    void* mapping = mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (mapping != MAP_FAILED) {
      mapping_ = mapping;
      data_ = static_cast<const unsigned char*>(mapping);
      madvise(mapping_, size_, MADV_SEQUENTIAL);
    }
  }
  ::close(fd);
  if (data_ || size_ == 0) return {};
    // Mapping can fail on some file systems: fall back to reading.
#endif
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return std::string("cannot open: ") + std::strerror(errno);
  std::error_code ec;
  size_ = static_cast<size_t>(std::filesystem::file_size(path, ec));
  if (ec) {
    std::fclose(file);
    return "cannot open: " + ec.message();
  }
  buffer_ = std::make_unique_for_overwrite<unsigned char[]>(std::max<size_t>(size_, 1));
  size_t total = 0;
  while (total < size_) {
    const size_t got = std::fread(buffer_.get() + total, 1, size_ - total, file);
    if (got == 0) break;
    total += got;
  }
  const bool read_error = std::ferror(file) != 0;
  std::fclose(file);
  if (read_error) return "read error";
  size_ = total;  // the file may have shrunk since file_size(); trust what was read
  data_ = buffer_.get();
  return {};
}

void FileContents::release_before(size_t end) {
#if TILESPLAT_HAS_MMAP
  if (!mapping_) return;
  const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  const size_t whole_pages = std::min(end, size_) / page * page;
  if (whole_pages <= released_) return;
  // A private read-only file mapping: dropped pages come back from the file if touched again.
  madvise(static_cast<unsigned char*>(mapping_) + released_, whole_pages - released_, MADV_DONTNEED);
  released_ = whole_pages;
#else
  (void)end;
#endif
}

void FileContents::release_all() const {
#if TILESPLAT_HAS_MMAP
  if (mapping_) madvise(mapping_, size_, MADV_DONTNEED);
#endif
}

void open_scene_file(const std::filesystem::path& path, FileContents& contents) {
  const std::string name = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec && status.type() != std::filesystem::file_type::not_found)
    fail(name, "cannot open: " + ec.message());
  if (!std::filesystem::exists(status)) fail(name, "cannot open: no such file");
  if (std::filesystem::is_directory(status)) fail(name, "cannot open: is a directory, not a file");
  if (!std::filesystem::is_regular_file(status)) fail(name, "cannot open: not a regular file");
  if (const std::string error = contents.open(path); !error.empty()) fail(name, error);
}

Container container_of(std::span<const std::byte> data) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  const auto starts_with = [&](std::string_view magic) {
    return data.size() >= magic.size() && std::memcmp(bytes, magic.data(), magic.size()) == 0;
  };
  if (starts_with("ply\n") || starts_with("ply\r\n")) return Container::kPly;
  if (starts_with("PK\x03\x04")) return Container::kZip;
  if (starts_with("glTF")) return Container::kGlb;
  if (is_spz(data)) return Container::kSpz;
  if (is_ksplat(data)) return Container::kKsplat;
  if (is_rad(data)) return Container::kRad;
  for (size_t i = 0; i < data.size(); ++i) {
    const char c = static_cast<char>(bytes[i]);
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;
    return c == '{' ? Container::kJson : Container::kUnknown;
  }
  return Container::kUnknown;
}

FileLoader sibling_loader(const std::filesystem::path& referrer) {
  return [referrer](const std::string& name) {
    if (!is_path_beside(name))
      fail(referrer.string(), "it names the file '" + name + "', which is not a path beside it");
    const std::filesystem::path path = referrer.parent_path() / name;
    FileContents contents;
    try {
      open_scene_file(path, contents);
    } catch (const SceneError& error) {
      fail(referrer.string(), "it names '" + name + "', which cannot be read (" + error.what() + ")");
    }
    return std::vector<unsigned char>(contents.data(), contents.data() + contents.size());
  };
}

bool is_path_beside(const std::string& name) {
  const std::filesystem::path relative(name);
  return !name.empty() && !relative.is_absolute() &&
         std::none_of(relative.begin(), relative.end(), [](const auto& part) { return part == ".."; });
}

float to_float(double value) {
  if (std::isfinite(value) && std::fabs(value) > static_cast<double>(std::numeric_limits<float>::max()))
    return value > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  return static_cast<float>(value);
}

double clamped_logit(double p) {
  constexpr double kEpsilon = 1e-6;
  const double clamped = std::clamp(p, kEpsilon, 1.0 - kEpsilon);
  return std::log(clamped / (1.0 - clamped));
}

void allocate_scene(GaussianScene& scene, size_t count, int sh_degree) {
  scene.sh_degree = sh_degree;
  scene.positions.resize(3 * count);
  scene.log_scales.resize(3 * count);
  scene.rotations.resize(4 * count);
  scene.opacity_logits.resize(count);
  scene.sh.resize(3 * static_cast<size_t>(scene.sh_coefficients()) * count);
  scene.normals.clear();
}

void require_bytes(std::string_view name, std::string_view what, uint64_t count, uint64_t bytes_each,
                   uint64_t available) {
  if (bytes_each != 0 && count > available / bytes_each)
    fail(name, std::string(what) + ": " + std::to_string(count) + " Gaussians of " +
                   std::to_string(bytes_each) + " bytes need more than the " + std::to_string(available) +
                   " bytes there are; the file is truncated or its count is wrong");
}

namespace {

std::string describe_value(float value) {
  if (std::isnan(value)) return "nan";
  return value > 0 ? "inf" : "-inf";
}

}  // namespace

void NonFiniteTally::record(size_t index, const std::string& property, float value) {
  if (options_.strict)
    fail(name_, "Gaussian " + std::to_string(index) + " has a non-finite value in " + property + " (" +
                    describe_value(value) + ") (strict mode)");
  ++dropped_;
  for (DroppedProperty& entry : by_property_) {
    if (entry.property == property) {
      ++entry.count;
      return;
    }
  }
  by_property_.push_back(DroppedProperty{property, 1, index});
}

void normalize_rotations(GaussianScene& scene) {
  const size_t count = scene.size();
  constexpr float kSmallest = std::numeric_limits<float>::min();
  for (size_t i = 0; i < count; ++i) {
    float* q = scene.rotations.data() + 4 * i;
    const bool vanishing = std::fabs(q[0]) < kSmallest && std::fabs(q[1]) < kSmallest &&
                           std::fabs(q[2]) < kSmallest && std::fabs(q[3]) < kSmallest;
    if (vanishing) {
      q[0] = 1.0f;
      q[1] = q[2] = q[3] = 0.0f;
      continue;
    }
    const double norm_squared = static_cast<double>(q[0]) * q[0] + static_cast<double>(q[1]) * q[1] +
                                static_cast<double>(q[2]) * q[2] + static_cast<double>(q[3]) * q[3];
    const double inverse_norm = 1.0 / std::sqrt(norm_squared);
    for (size_t j = 0; j < 4; ++j) q[j] = static_cast<float>(q[j] * inverse_norm);
  }
}

namespace {

// The first non-finite value of Gaussian i, by its PLY property name, in the trainer's order.
std::string first_non_finite(const GaussianScene& scene, size_t i, float* value) {
  const auto check = [&](const float* values, size_t n, auto&& name_of) -> std::string {
    for (size_t j = 0; j < n; ++j)
      if (!std::isfinite(values[j])) {
        *value = values[j];
        return name_of(j);
      }
    return {};
  };
  static constexpr const char* kAxes[] = {"x", "y", "z"};
  const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
  const size_t rest = coefficients - 1;
  std::string name = check(scene.positions.data() + 3 * i, 3, [](size_t j) { return std::string(kAxes[j]); });
  if (name.empty())
    name = check(scene.sh.data() + 3 * coefficients * i, 3 * coefficients, [&](size_t j) {
      const size_t k = j / 3;
      const size_t channel = j % 3;
      if (k == 0) return "f_dc_" + std::to_string(channel);
      return "f_rest_" + std::to_string(channel * rest + k - 1);
    });
  if (name.empty())
    name = check(scene.opacity_logits.data() + i, 1, [](size_t) { return std::string("opacity"); });
  if (name.empty())
    name = check(scene.log_scales.data() + 3 * i, 3, [](size_t j) { return "scale_" + std::to_string(j); });
  if (name.empty())
    name = check(scene.rotations.data() + 4 * i, 4, [](size_t j) { return "rot_" + std::to_string(j); });
  return name;
}

bool all_finite(const float* values, size_t n) {
  for (size_t j = 0; j < n; ++j)
    if (!std::isfinite(values[j])) return false;
  return true;
}

}  // namespace

std::vector<size_t> non_finite_gaussians(const GaussianScene& scene, size_t first, NonFiniteTally& tally) {
  const size_t count = scene.size();
  const size_t sh_stride = 3 * static_cast<size_t>(scene.sh_coefficients());
  std::vector<size_t> found;
  for (size_t i = 0; i < count; ++i) {
    const bool finite =
        all_finite(scene.positions.data() + 3 * i, 3) && all_finite(scene.log_scales.data() + 3 * i, 3) &&
        all_finite(scene.rotations.data() + 4 * i, 4) && std::isfinite(scene.opacity_logits[i]) &&
        all_finite(scene.sh.data() + sh_stride * i, sh_stride);
    if (finite) continue;
    float value = 0;
    const std::string property = first_non_finite(scene, i, &value);
    tally.record(first + i, property, value);
    found.push_back(i);
  }
  return found;
}

void finish_scene(GaussianScene& scene, std::string_view name, const LoadOptions& options, std::string format,
                  std::string version, LoadReport* report) {
  const size_t count = scene.size();
  const size_t sh_stride = 3 * static_cast<size_t>(scene.sh_coefficients());
  NonFiniteTally tally(name, options);
  const std::vector<size_t> dropped = non_finite_gaussians(scene, 0, tally);
  size_t kept = 0;
  for (size_t i = 0, next_dropped = 0; i < count; ++i) {
    if (next_dropped < dropped.size() && dropped[next_dropped] == i) {
      ++next_dropped;
      continue;
    }
    if (kept != i) {
      std::copy_n(scene.positions.data() + 3 * i, 3, scene.positions.data() + 3 * kept);
      std::copy_n(scene.log_scales.data() + 3 * i, 3, scene.log_scales.data() + 3 * kept);
      std::copy_n(scene.rotations.data() + 4 * i, 4, scene.rotations.data() + 4 * kept);
      scene.opacity_logits[kept] = scene.opacity_logits[i];
      std::copy_n(scene.sh.data() + sh_stride * i, sh_stride, scene.sh.data() + sh_stride * kept);
    }
    ++kept;
  }
  if (kept != count) {
    scene.positions.resize(3 * kept);
    scene.log_scales.resize(3 * kept);
    scene.rotations.resize(4 * kept);
    scene.opacity_logits.resize(kept);
    scene.sh.resize(sh_stride * kept);
  }
  normalize_rotations(scene);
  if (report) {
    LoadReport result;
    result.format = std::move(format);
    result.version = std::move(version);
    result.gaussians_in_file = count;
    result.dropped = tally.dropped();
    result.dropped_by_property = tally.take();
    *report = std::move(result);
  }
}

}  // namespace tilesplat::detail
