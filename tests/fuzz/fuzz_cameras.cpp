// libFuzzer harness for the camera readers: COLMAP models (binary and text, one file fuzzed beside a
// valid other), transforms.json, the trainer's cameras.json and camera path keyframes. The first
// byte picks the reader, the rest is the file. Every input must load cameras a renderer accepts or
// throw a SceneError that names the file; see tests/fuzz/README.md.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_checks.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/camera_sets.h"

namespace {

namespace fs = std::filesystem;

// A folder of this process's own (libFuzzer may run several processes side by side).
const fs::path& work_folder() {
  static const fs::path folder = [] {
    const fs::path path =
        fs::temp_directory_path() / ("tilesplat_fuzz_cameras_" + std::to_string(::getpid()));
    fs::create_directories(path);
    return path;
  }();
  return folder;
}

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

template <typename T>
void put(std::string& bytes, T value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof value);
}

// One valid PINHOLE camera (id 1) and one image of it, for the file that is not being fuzzed.
std::string valid_cameras_bin() {
  std::string bytes;
  put<uint64_t>(bytes, 1);
  put<int32_t>(bytes, 1);
  put<int32_t>(bytes, 1);
  put<uint64_t>(bytes, 64);
  put<uint64_t>(bytes, 48);
  for (double p : {50.0, 50.0, 32.0, 24.0}) put<double>(bytes, p);
  return bytes;
}
std::string valid_images_bin() {
  std::string bytes;
  put<uint64_t>(bytes, 1);
  put<int32_t>(bytes, 7);
  for (double p : {1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 4.0}) put<double>(bytes, p);
  put<int32_t>(bytes, 1);
  bytes += std::string("a.png") + '\0';
  put<uint64_t>(bytes, 0);
  return bytes;
}
constexpr const char* kValidCamerasTxt = "1 PINHOLE 64 48 50 50 32 24\n";
constexpr const char* kValidImagesTxt = "7 1 0 0 0 0 0 4 1 a.png\n\n";

void check_camera(const tilesplat::Camera& camera) {
  tilesplat::validate(camera);  // throws std::invalid_argument, which libFuzzer reports
  // The lens's limits (a scan for where its mapping folds, undistorting the image's border) end for any
  // coefficients; a point in front of the camera projects to finite numbers or not at all, and the ray
  // through the image's centre is a unit vector or none.
  if (const auto pixel = camera.project({0.1, -0.05, 2.0}))
    FUZZ_CHECK(std::isfinite((*pixel)[0]) && std::isfinite((*pixel)[1]));
  if (const auto ray = camera.ray_direction(camera.cx, camera.cy))
    FUZZ_CHECK(std::fabs(std::hypot((*ray)[0], (*ray)[1], (*ray)[2]) - 1) < 1e-6);
  const auto& r = camera.rotation;
  for (size_t i = 0; i < 3; ++i) {
    const double norm = r[i * 3] * r[i * 3] + r[i * 3 + 1] * r[i * 3 + 1] + r[i * 3 + 2] * r[i * 3 + 2];
    FUZZ_CHECK(std::fabs(norm - 1) < 1e-2);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const fs::path folder = work_folder() / "model";
  fs::remove_all(folder);
  fs::create_directories(folder);
  const int reader = data[0] % 7;
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  fs::path file;
  switch (reader) {
    case 0:
      write(file = folder / "cameras.bin", bytes), write(folder / "images.bin", valid_images_bin());
      break;
    case 1:
      write(folder / "cameras.bin", valid_cameras_bin()), write(file = folder / "images.bin", bytes);
      break;
    case 2:
      write(file = folder / "cameras.txt", bytes), write(folder / "images.txt", kValidImagesTxt);
      break;
    case 3:
      write(folder / "cameras.txt", kValidCamerasTxt), write(file = folder / "images.txt", bytes);
      break;
    case 4:
      write(file = folder / "transforms.json", "{" + bytes);
      break;
    case 5:
      write(file = folder / "cameras.json", bytes);
      break;
    default:
      write(file = folder / "keys.json", bytes);
      break;
  }
  try {
    if (reader == 6) {
      const tilesplat::CameraPath path = tilesplat::load_camera_path(file);
      FUZZ_CHECK(path.keys.size() >= 2);
      for (const tilesplat::Camera& camera : tilesplat::sample_camera_path(path, 3, 64, 48))
        check_camera(camera);
    } else {
      const auto views = reader == 5 ? tilesplat::load_cameras_json(file) : tilesplat::load_camera_set(file);
      FUZZ_CHECK(!views.empty());
      for (const tilesplat::CameraView& view : views) check_camera(view.camera);
    }
  } catch (const tilesplat::SceneError& error) {
    // The message names the file read (either file of a COLMAP model).
    FUZZ_CHECK(std::string(error.what()).starts_with(folder.string()));
  }
  return 0;
}
