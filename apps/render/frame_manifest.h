// The manifest of a many-frame render: one JSON line per finished frame, appended only after its
// files are complete, so that a re-run can skip what is done and a crash loses at most the frames
// in flight. Shards each append to their own file; merge_manifests checks that together they cover
// every frame exactly once.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "frame_sequence.h"
#include "tilesplat/camera.h"

namespace tilesplat::cli {

struct ManifestEntry {
  int frame = 0;       // the frame's position in the run's sequence, 0 to frames - 1
  int frames = 0;      // how many frames the whole run (all shards) has
  int number = 0;      // the number in its file name: the view index, or the frame of a path
  std::string camera;  // "view 3 of cameras.json (img_0003)", "orbit frame 5 of 100", ...
  // The camera's values, exactly (camera_pose_text): the description stays the same when an orbit's
  // elevation or a cameras.json changes, the values do not. "" in manifests written before it.
  std::string pose;
  int width = 0, height = 0;
  std::string file;  // the EXR, relative to the manifest's folder
  uint64_t bytes = 0;
  std::string sha256;  // of the EXR
  std::string png;     // the preview, relative to the manifest's folder ("" when none)
  std::string png_sha256;
  double gpu_ms = 0;
  double resident_mib = 0;  // the process's resident memory when the frame was done (a leak shows here)
  std::string settings;     // everything else that changes the files (sort, modes, effects, EXR options)
};

std::string to_json_line(const ManifestEntry& entry);  // one line, no newline

// fx fy cx cy, the rotation's 9 and the position's 3 values, each as its shortest exact decimal; then,
// for a model other than the pinhole, its name and its 8 coefficients.
std::string camera_pose_text(const Camera& camera);

// "manifest.jsonl" for a run in one shard, "manifest.shard-I-of-N.jsonl" for a shard.
std::string manifest_file_name(const Shard& shard);

// Every line of every manifest*.jsonl in `folder`, in file then line order. A last line without
// its newline (a write cut off by a kill) is ignored; any other line that does not parse throws
// std::runtime_error naming the file and line.
struct ManifestLine {
  std::filesystem::path manifest;
  ManifestEntry entry;
};
std::vector<ManifestLine> read_manifests(const std::filesystem::path& folder);

// Whether the entry's files exist in `folder` with the recorded size and SHA-256 (the EXR's, and
// the preview's when it has one).
bool files_match(const std::filesystem::path& folder, const ManifestEntry& entry);

// Appends lines to one manifest. Each line goes out in one write() with O_APPEND and is synced to
// the disk before append() returns, so a line is either complete or (when killed mid-write) a
// torn last line that read_manifests ignores, and that the next appender cuts off before it appends.
class ManifestAppender {
 public:
  explicit ManifestAppender(std::filesystem::path path);
  ~ManifestAppender();
  ManifestAppender(const ManifestAppender&) = delete;
  ManifestAppender& operator=(const ManifestAppender&) = delete;
  void append(const ManifestEntry& entry);
  const std::filesystem::path& path() const { return path_; }

 private:
  void drop_torn_last_line();

  std::filesystem::path path_;
  int fd_ = -1;
};

// --merge-manifests: reads the shard manifests of `folder` (manifest.shard-*.jsonl), checks that
// they agree on the number of frames and together cover each frame exactly once with files that
// match their checksums (a frame re-rendered within one shard counts once, by its last line), and
// writes the union, ordered by frame, to folder/manifest.jsonl. Throws std::runtime_error naming
// the missing frames, the frames two shards both claim, or the files that do not match.
struct MergeResult {
  size_t manifests = 0;
  size_t frames = 0;
  std::filesystem::path merged;
};
MergeResult merge_manifests(const std::filesystem::path& folder);

// "3, 7-9, 12": a sorted list of frame numbers with runs shortened, at most `limit` items.
std::string describe_frames(const std::vector<int>& frames, size_t limit = 20);

}  // namespace tilesplat::cli
