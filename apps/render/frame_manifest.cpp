#include "frame_manifest.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "cli.h"
#include "sha256.h"

namespace tilesplat::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Built by appending: GCC 12 misreports '"\'" + text + "\'"' under -Wrestrict.
std::string in_quotes(const fs::path& path) {
  std::string quoted(1, '\'');
  quoted += path.string();
  quoted += '\'';
  return quoted;
}

ManifestEntry entry_of(const json& line) {
  ManifestEntry entry;
  entry.frame = line.at("frame").get<int>();
  entry.frames = line.at("frames").get<int>();
  entry.number = line.at("number").get<int>();
  entry.camera = line.at("camera").get<std::string>();
  entry.pose = line.value("pose", "");
  entry.width = line.at("width").get<int>();
  entry.height = line.at("height").get<int>();
  entry.file = line.at("file").get<std::string>();
  entry.bytes = line.at("bytes").get<uint64_t>();
  entry.sha256 = line.at("sha256").get<std::string>();
  entry.png = line.value("png", "");
  entry.png_sha256 = line.value("png_sha256", "");
  entry.gpu_ms = line.at("gpu_ms").get<double>();
  entry.resident_mib = line.value("resident_mib", 0.0);
  entry.settings = line.at("settings").get<std::string>();
  if (entry.frames < 1 || entry.frame < 0 || entry.frame >= entry.frames)
    throw std::runtime_error("frame " + std::to_string(entry.frame) + " is outside 0 to frames - 1 (" +
                             std::to_string(entry.frames) + " frames)");
  return entry;
}

bool file_matches(const fs::path& path, uint64_t bytes, const std::string& sha256) {
  std::error_code error;
  if (!fs::is_regular_file(path, error) || fs::file_size(path, error) != bytes || error) return false;
  try {
    return sha256_file_hex(path) == sha256;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

std::string camera_pose_text(const Camera& camera) {
  std::string text;
  auto add = [&text](double value) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;  // shortest round trip
    if (!text.empty()) text += ' ';
    text.append(buffer, end);
  };
  for (const double value : {camera.fx, camera.fy, camera.cx, camera.cy}) add(value);
  for (const double value : camera.rotation) add(value);
  for (const double value : camera.position) add(value);
  if (camera.model != CameraModel::kPinhole) {  // a pinhole's line stays as it always was
    text += ' ';
    text += camera_model_name(camera.model);
    for (const double value : camera.distortion) add(value);
  }
  return text;
}

std::string to_json_line(const ManifestEntry& entry) {
  nlohmann::ordered_json line = {
      {"frame", entry.frame},      {"frames", entry.frames}, {"number", entry.number},
      {"camera", entry.camera},    {"pose", entry.pose},     {"width", entry.width},
      {"height", entry.height},    {"file", entry.file},     {"bytes", entry.bytes},
      {"sha256", entry.sha256},    {"gpu_ms", entry.gpu_ms}, {"resident_mib", entry.resident_mib},
      {"settings", entry.settings}};
  if (!entry.png.empty()) {
    line["png"] = entry.png;
    line["png_sha256"] = entry.png_sha256;
  }
  return line.dump();
}

std::string manifest_file_name(const Shard& shard) {
  if (shard.count == 1) return "manifest.jsonl";
  return "manifest.shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) + ".jsonl";
}

std::vector<ManifestLine> read_manifests(const fs::path& folder) {
  std::vector<fs::path> manifests;
  std::error_code error;
  for (const auto& item : fs::directory_iterator(folder, error)) {
    const std::string name = item.path().filename().string();
    if (name.starts_with("manifest") && name.ends_with(".jsonl") && item.is_regular_file(error))
      manifests.push_back(item.path());
  }
  std::sort(manifests.begin(), manifests.end());

  std::vector<ManifestLine> lines;
  for (const fs::path& manifest : manifests) {
    std::ifstream stream(manifest, std::ios::binary);
    if (!stream) throw std::runtime_error("cannot read " + in_quotes(manifest));
    std::ostringstream buffer;
    buffer << stream.rdbuf();
    const std::string text = buffer.str();
    size_t start = 0;
    for (size_t number = 1; start < text.size(); ++number) {
      const size_t end = text.find('\n', start);
      if (end == std::string::npos) break;  // a torn last line: its frame was still in flight
      const std::string line = text.substr(start, end - start);
      start = end + 1;
      if (line.empty()) continue;
      try {
        lines.push_back({manifest, entry_of(json::parse(line))});
      } catch (const std::exception& problem) {
        throw std::runtime_error(in_quotes(manifest) + " line " + std::to_string(number) +
                                 " is not a manifest entry: " + one_line(problem.what()) +
                                 " (delete the line, or the manifest to start over)");
      }
    }
  }
  return lines;
}

bool files_match(const fs::path& folder, const ManifestEntry& entry) {
  if (!file_matches(folder / entry.file, entry.bytes, entry.sha256)) return false;
  if (entry.png.empty()) return true;
  std::error_code error;
  const fs::path png = folder / entry.png;
  return fs::is_regular_file(png, error) && sha256_file_hex(png) == entry.png_sha256;
}

ManifestAppender::ManifestAppender(fs::path path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw std::runtime_error("cannot open " + in_quotes(path_) + " for appending: " + std::strerror(errno));
  drop_torn_last_line();
}

// A run killed while it wrote a line leaves that line without its newline. Readers ignore it (its frame
// was still in flight), but a line appended after it would join it into one malformed line: cut it off.
void ManifestAppender::drop_torn_last_line() {
  const off_t size = ::lseek(fd_, 0, SEEK_END);
  if (size <= 0) return;
  std::string text(static_cast<size_t>(size), '\0');
  if (::pread(fd_, text.data(), text.size(), 0) != size)
    throw std::runtime_error("cannot read " + in_quotes(path_) + ": " + std::strerror(errno));
  const size_t last_newline = text.rfind('\n');
  const off_t keep = last_newline == std::string::npos ? 0 : static_cast<off_t>(last_newline + 1);
  if (keep != size && ::ftruncate(fd_, keep) != 0)
    throw std::runtime_error("cannot cut the torn last line of " + in_quotes(path_) + ": " +
                             std::strerror(errno));
}

ManifestAppender::~ManifestAppender() {
  if (fd_ >= 0) ::close(fd_);
}

void ManifestAppender::append(const ManifestEntry& entry) {
  const std::string line = to_json_line(entry) + "\n";
  const ssize_t written = ::write(fd_, line.data(), line.size());
  if (written != static_cast<ssize_t>(line.size()))
    throw std::runtime_error("cannot append to " + in_quotes(path_) + ": " +
                             (written < 0 ? std::strerror(errno) : "short write"));
  if (::fsync(fd_) != 0 && errno != EINVAL)
    throw std::runtime_error("cannot sync " + in_quotes(path_) + ": " + std::strerror(errno));
}

std::string describe_frames(const std::vector<int>& frames, size_t limit) {
  std::vector<int> sorted = frames;
  std::sort(sorted.begin(), sorted.end());
  std::string text;
  size_t items = 0;
  for (size_t i = 0; i < sorted.size(); ++i) {
    size_t j = i;
    while (j + 1 < sorted.size() && sorted[j + 1] == sorted[j] + 1) ++j;
    if (items == limit) {
      text += ", ... (" + std::to_string(sorted.size()) + " in all)";
      return text;
    }
    if (!text.empty()) text += ", ";
    text += std::to_string(sorted[i]);
    if (j > i) {
      text += '-';
      text += std::to_string(sorted[j]);
    }
    ++items;
    i = j;
  }
  return text;
}

MergeResult merge_manifests(const fs::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) throw std::runtime_error(in_quotes(folder) + " is not a folder");
  std::vector<ManifestLine> lines;
  for (ManifestLine& line : read_manifests(folder))
    if (line.manifest.filename().string().starts_with("manifest.shard-")) lines.push_back(std::move(line));
  if (lines.empty())
    throw std::runtime_error(in_quotes(folder) +
                             " has no shard manifests (manifest.shard-I-of-N.jsonl) to merge");

  // The last line of each manifest for a frame is its newest render.
  std::map<int, std::map<fs::path, ManifestEntry>> claims;  // frame -> manifest -> entry
  std::set<fs::path> manifests;
  const int frames = lines.front().entry.frames;
  for (const ManifestLine& line : lines) {
    if (line.entry.frames != frames)
      throw std::runtime_error(
          "the manifests disagree on the number of frames: " + in_quotes(lines.front().manifest.filename()) +
          " has " + std::to_string(frames) + ", " + in_quotes(line.manifest.filename()) + " " +
          std::to_string(line.entry.frames) + " (are they from different runs?)");
    claims[line.entry.frame][line.manifest] = line.entry;
    manifests.insert(line.manifest);
  }

  std::vector<int> missing, mismatched;
  std::string twice;
  std::string merged;
  for (int frame = 0; frame < frames; ++frame) {
    const auto found = claims.find(frame);
    if (found == claims.end()) {
      missing.push_back(frame);
      continue;
    }
    if (found->second.size() > 1 && twice.empty()) {
      twice = "frame " + std::to_string(frame) + " is in both " +
              in_quotes(found->second.begin()->first.filename()) + " and " +
              in_quotes(std::next(found->second.begin())->first.filename());
    }
    const ManifestEntry& entry = found->second.begin()->second;
    if (!files_match(folder, entry)) mismatched.push_back(frame);
    merged += to_json_line(entry) + "\n";
  }
  if (!twice.empty()) throw std::runtime_error(twice + ": each frame must belong to exactly one shard");
  if (!missing.empty())
    throw std::runtime_error(std::to_string(missing.size()) + " of " + std::to_string(frames) +
                             " frames are in no manifest: " + describe_frames(missing) +
                             " (re-run the shards that render them)");
  if (!mismatched.empty())
    throw std::runtime_error(std::to_string(mismatched.size()) +
                             " frames' files are missing or do not match their manifest's checksum: " +
                             describe_frames(mismatched) + " (re-run their shards to render them again)");
  MergeResult result;
  result.manifests = manifests.size();
  result.frames = static_cast<size_t>(frames);
  result.merged = folder / "manifest.jsonl";
  tilesplat::write_file_atomically(result.merged, merged);
  return result;
}

}  // namespace tilesplat::cli
