// Reads COLMAP sparse models (cameras and images, binary or text) as camera views. The layouts are
// COLMAP's read_write_model: little-endian, cameras.bin = u64 count, then per camera i32 id,
// i32 model, u64 width, u64 height, f64 params[]; images.bin = u64 count, then per image i32 id,
// f64 qw qx qy qz, f64 tx ty tz, i32 camera id, a NUL-terminated name, u64 point count and
// 24 bytes per point. The pose maps world to camera: x_cam = R(q) x_world + t.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tilesplat/camera_sets.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;

struct ModelInfo {
  const char* name;
  size_t parameters;
};
// COLMAP's camera models by id (colmap/sensor/models.h).
constexpr std::array<ModelInfo, 11> kModels = {{{"SIMPLE_PINHOLE", 3},
                                                {"PINHOLE", 4},
                                                {"SIMPLE_RADIAL", 4},
                                                {"RADIAL", 5},
                                                {"OPENCV", 8},
                                                {"OPENCV_FISHEYE", 8},
                                                {"FULL_OPENCV", 12},
                                                {"FOV", 5},
                                                {"SIMPLE_RADIAL_FISHEYE", 4},
                                                {"RADIAL_FISHEYE", 5},
                                                {"THIN_PRISM_FISHEYE", 12}}};

struct ColmapCamera {
  std::string model;
  uint64_t width = 0, height = 0;
  std::vector<double> params;
};

struct ColmapImage {
  int id = 0;
  std::array<double, 4> q{};  // w, x, y, z
  std::array<double, 3> t{};
  int camera_id = 0;
  std::string name;
};

std::string read_whole_file(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw SceneError(path.string() + ": cannot open file");
  std::ostringstream contents;
  contents << stream.rdbuf();
  return contents.str();
}

// Little-endian fields off a byte string, every read checked against its end.
class BinaryCursor {
 public:
  BinaryCursor(const std::string& bytes, std::string file) : bytes_(bytes), file_(std::move(file)) {}

  template <typename T>
  T read(const char* what) {
    static_assert(std::endian::native == std::endian::little, "COLMAP files are little-endian");
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  std::string read_name() {
    const size_t end = bytes_.find('\0', offset_);
    if (end == std::string::npos) fail("truncated: an image name has no terminating NUL");
    std::string name = bytes_.substr(offset_, end - offset_);
    offset_ = end + 1;
    return name;
  }
  void skip(uint64_t count, uint64_t size, const char* what) {
    if (count > (bytes_.size() - offset_) / size)
      fail(std::string("truncated: ") + what + " run past the end");
    offset_ += static_cast<size_t>(count * size);
  }
  // A count of records of at least `size` bytes each must fit in what is left.
  uint64_t count(uint64_t size, const char* what) {
    const auto n = read<uint64_t>(what);
    if (n > (bytes_.size() - offset_) / size)
      fail("claims " + std::to_string(n) + " " + what + ", more than the file holds");
    return n;
  }
  bool at_end() const { return offset_ == bytes_.size(); }
  [[noreturn]] void fail(const std::string& message) const { throw SceneError(file_ + ": " + message); }

 private:
  void need(size_t size, const char* what) const {
    if (bytes_.size() - offset_ < size) fail(std::string("truncated in ") + what);
  }
  const std::string& bytes_;
  std::string file_;
  size_t offset_ = 0;
};

double finite(double value, const std::string& file, const std::string& what) {
  if (!std::isfinite(value)) throw SceneError(file + ": " + what + " is not a finite number");
  return value;
}

std::map<int, ColmapCamera> read_cameras_bin(const fs::path& path) {
  const std::string bytes = read_whole_file(path);
  BinaryCursor in(bytes, path.string());
  std::map<int, ColmapCamera> cameras;
  const uint64_t count = in.count(24, "cameras");
  for (uint64_t k = 0; k < count; ++k) {
    const auto id = in.read<int32_t>("a camera id");
    const auto model = in.read<int32_t>("a camera model");
    if (model < 0 || static_cast<size_t>(model) >= kModels.size())
      in.fail("camera " + std::to_string(id) + " has unknown model id " + std::to_string(model));
    ColmapCamera camera;
    camera.model = kModels[static_cast<size_t>(model)].name;
    camera.width = in.read<uint64_t>("a camera width");
    camera.height = in.read<uint64_t>("a camera height");
    for (size_t p = 0; p < kModels[static_cast<size_t>(model)].parameters; ++p)
      camera.params.push_back(in.read<double>("camera parameters"));
    if (!cameras.emplace(id, camera).second) in.fail("camera id " + std::to_string(id) + " appears twice");
  }
  return cameras;
}

std::vector<ColmapImage> read_images_bin(const fs::path& path) {
  const std::string bytes = read_whole_file(path);
  BinaryCursor in(bytes, path.string());
  std::vector<ColmapImage> images;
  const uint64_t count = in.count(4 + 7 * 8 + 4 + 1 + 8, "images");
  for (uint64_t k = 0; k < count; ++k) {
    ColmapImage image;
    image.id = in.read<int32_t>("an image id");
    for (double& c : image.q) c = in.read<double>("an image rotation");
    for (double& c : image.t) c = in.read<double>("an image translation");
    image.camera_id = in.read<int32_t>("an image's camera id");
    image.name = in.read_name();
    const auto points = in.read<uint64_t>("an image's point count");
    in.skip(points, 24, "an image's 2D points");
    images.push_back(std::move(image));
  }
  return images;
}

// The lines of a COLMAP text file that are not comments or blank, with their line numbers.
std::vector<std::pair<size_t, std::string>> data_lines(const fs::path& path, bool keep_blank) {
  std::istringstream in(read_whole_file(path));
  std::vector<std::pair<size_t, std::string>> lines;
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty() && line[0] == '#') continue;
    if (line.find_first_not_of(" \t") == std::string::npos && !keep_blank) continue;
    lines.emplace_back(number, line);
  }
  return lines;
}

[[noreturn]] void fail_line(const fs::path& path, size_t line, const std::string& message) {
  throw SceneError(path.string() + ": line " + std::to_string(line) + ": " + message);
}

std::map<int, ColmapCamera> read_cameras_txt(const fs::path& path) {
  std::map<int, ColmapCamera> cameras;
  for (const auto& [number, line] : data_lines(path, false)) {
    std::istringstream fields(line);
    long long id = 0;
    ColmapCamera camera;
    long long width = 0, height = 0;
    if (!(fields >> id >> camera.model >> width >> height))
      fail_line(path, number, "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS...");
    if (width < 0 || height < 0) fail_line(path, number, "negative image size");
    camera.width = static_cast<uint64_t>(width);
    camera.height = static_cast<uint64_t>(height);
    const auto model = std::find_if(kModels.begin(), kModels.end(),
                                    [&](const ModelInfo& info) { return camera.model == info.name; });
    if (model == kModels.end()) fail_line(path, number, "unknown camera model '" + camera.model + "'");
    for (double value; fields >> value;) camera.params.push_back(value);
    if (!fields.eof() || camera.params.size() != model->parameters)
      fail_line(path, number,
                camera.model + " takes " + std::to_string(model->parameters) + " numeric parameters");
    if (id < INT32_MIN || id > INT32_MAX || !cameras.emplace(static_cast<int>(id), camera).second)
      fail_line(path, number, "camera id " + std::to_string(id) + " is out of range or appears twice");
  }
  return cameras;
}

std::vector<ColmapImage> read_images_txt(const fs::path& path) {
  // Two lines per image: the pose, then its 2D points (an empty line when it has none).
  const auto lines = data_lines(path, true);
  std::vector<ColmapImage> images;
  for (size_t k = 0; k < lines.size(); ++k) {
    const auto& [number, line] = lines[k];
    if (line.find_first_not_of(" \t") == std::string::npos) continue;  // a trailing blank line
    std::istringstream fields(line);
    ColmapImage image;
    long long id = 0, camera_id = 0;
    if (!(fields >> id >> image.q[0] >> image.q[1] >> image.q[2] >> image.q[3] >> image.t[0] >> image.t[1] >>
          image.t[2] >> camera_id) ||
        id < INT32_MIN || id > INT32_MAX || camera_id < INT32_MIN || camera_id > INT32_MAX)
      fail_line(path, number, "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    std::getline(fields >> std::ws, image.name);
    if (image.name.empty()) fail_line(path, number, "the image has no NAME");
    image.id = static_cast<int>(id);
    image.camera_id = static_cast<int>(camera_id);
    images.push_back(std::move(image));
    ++k;  // its points line
  }
  return images;
}

// The camera's intrinsics and model from COLMAP's parameters (colmap/sensor/models.h): the pinholes, the
// OpenCV family (SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV: CameraModel::kOpenCV) and the fisheyes whose
// angle mapping is Kannala-Brandt's (OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE:
// CameraModel::kFisheye). FOV and THIN_PRISM_FISHEYE are refused by name.
void set_intrinsics(Camera& camera, const ColmapCamera& source, const std::string& camera_where,
                    const fs::path& cameras_file) {
  const std::string& model = source.model;
  const auto& p = source.params;
  auto number = [&](size_t index, const char* what) { return finite(p[index], cameras_file.string(), what); };
  // SIMPLE_* and RADIAL* have one focal length and no fy: their parameters start f cx cy.
  const bool one_focal = model == "SIMPLE_PINHOLE" || model == "SIMPLE_RADIAL" || model == "RADIAL" ||
                         model == "SIMPLE_RADIAL_FISHEYE" || model == "RADIAL_FISHEYE";
  if (model == "FOV" || model == "THIN_PRISM_FISHEYE")
    throw SceneError(
        camera_where + " uses the " + model +
        " model, which the renderer does not have (it has PINHOLE, SIMPLE_PINHOLE, SIMPLE_RADIAL, "
        "RADIAL, OPENCV, FULL_OPENCV, OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE and RADIAL_FISHEYE): "
        "undistort the model to PINHOLE first (colmap image_undistorter)");
  camera.fx = number(0, "a focal length");
  camera.fy = one_focal ? camera.fx : number(1, "a focal length");
  const size_t centre = one_focal ? 1 : 2;
  camera.cx = number(centre, "a principal point");
  camera.cy = number(centre + 1, "a principal point");
  if (!(camera.fx > 0 && camera.fy > 0)) throw SceneError(camera_where + ": focal lengths must be positive");
  const size_t first = centre + 2;  // the first distortion parameter
  auto coefficient = [&](size_t index) { return number(index, "a distortion coefficient"); };
  auto& k = camera.distortion;
  if (model == "SIMPLE_RADIAL" || model == "RADIAL" || model == "OPENCV" || model == "FULL_OPENCV") {
    camera.model = CameraModel::kOpenCV;
    k[0] = coefficient(first);                                    // k1
    if (model != "SIMPLE_RADIAL") k[1] = coefficient(first + 1);  // k2
    if (model == "OPENCV" || model == "FULL_OPENCV")
      for (size_t i = 2; i < p.size() - first; ++i) k[i] = coefficient(first + i);  // p1 p2 (k3 k4 k5 k6)
  } else if (model == "OPENCV_FISHEYE" || model == "SIMPLE_RADIAL_FISHEYE" || model == "RADIAL_FISHEYE") {
    camera.model = CameraModel::kFisheye;
    for (size_t i = 0; i < p.size() - first; ++i) k[i] = coefficient(first + i);  // k1 (k2 (k3 k4))
  }
  try {
    validate(camera);
  } catch (const std::invalid_argument& error) {
    throw SceneError(camera_where + ": " + error.what());
  }
}

CameraView to_view(const ColmapImage& image, const std::map<int, ColmapCamera>& cameras,
                   const fs::path& images_file, const fs::path& cameras_file) {
  const std::string where =
      images_file.string() + ": image " + std::to_string(image.id) + " ('" + image.name + "')";
  const auto found = cameras.find(image.camera_id);
  if (found == cameras.end())
    throw SceneError(where + ": camera " + std::to_string(image.camera_id) + " is not in " +
                     cameras_file.filename().string());
  const ColmapCamera& source = found->second;
  const std::string camera_where = cameras_file.string() + ": camera " + std::to_string(image.camera_id);
  if (source.width < 1 || source.height < 1 || source.width > (1u << 20) || source.height > (1u << 20))
    throw SceneError(camera_where + ": image size " + std::to_string(source.width) + "x" +
                     std::to_string(source.height) + " is impossible");

  CameraView view;
  view.id = image.id;
  view.name = image.name;
  Camera& camera = view.camera;
  camera.width = static_cast<int>(source.width);
  camera.height = static_cast<int>(source.height);
  set_intrinsics(camera, source, camera_where, cameras_file);
  std::array<double, 4> q = image.q;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!std::isfinite(norm) || !(norm > 1e-6))
    throw SceneError(where + ": its rotation quaternion is not a rotation");
  for (double& c : q) c /= norm;
  for (double c : image.t) finite(c, images_file.string(), "an image translation");
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  camera.rotation = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                     2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                     2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
  // The centre: x_cam = 0 at x_world = -R^T t.
  const auto& r = camera.rotation;
  for (size_t k = 0; k < 3; ++k)
    camera.position[k] = -(r[k] * image.t[0] + r[3 + k] * image.t[1] + r[6 + k] * image.t[2]);
  return view;
}

}  // namespace

std::vector<CameraView> load_colmap_cameras(const fs::path& path) {
  fs::path folder = path;
  std::error_code error;
  if (!fs::is_directory(path, error)) folder = path.parent_path();
  if (folder.empty()) folder = ".";
  if (!fs::exists(folder / "cameras.bin", error) && !fs::exists(folder / "cameras.txt", error) &&
      fs::is_directory(folder / "sparse" / "0", error))
    folder = folder / "sparse" / "0";

  const bool binary = fs::exists(folder / "cameras.bin", error) || path.extension() == ".bin";
  const std::string extension = binary ? ".bin" : ".txt";
  const fs::path cameras_file = folder / ("cameras" + extension);
  const fs::path images_file = folder / ("images" + extension);
  for (const fs::path& file : {cameras_file, images_file})
    if (!fs::is_regular_file(file, error))
      throw SceneError(file.string() + ": not found (a COLMAP model is a folder with cameras" + extension +
                       " and images" + extension + ")");

  const auto cameras = binary ? read_cameras_bin(cameras_file) : read_cameras_txt(cameras_file);
  auto images = binary ? read_images_bin(images_file) : read_images_txt(images_file);
  if (images.empty()) throw SceneError(images_file.string() + ": the model has no registered images");
  std::stable_sort(images.begin(), images.end(),
                   [](const ColmapImage& a, const ColmapImage& b) { return a.name < b.name; });
  std::vector<CameraView> views;
  views.reserve(images.size());
  for (const ColmapImage& image : images) views.push_back(to_view(image, cameras, images_file, cameras_file));
  return views;
}

}  // namespace tilesplat
