// tilesplat-bench --formats: what each file format costs, measured against the lossless PLY of the
// same scene: size and bytes per Gaussian, load time and peak memory, the error of every decoded
// attribute, and the image error at the chosen views.
//
// Compressed formats may reorder the Gaussians (SOG and compressed PLY sort them along a Morton
// curve), so before the attributes are compared each Gaussian of a file is matched to one of the
// reference: by index when the file keeps the order, else to the nearest reference mean. Which one
// was used is reported, with how many reference Gaussians the matching reached.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat::formats {

// The largest absolute difference of each attribute between matched Gaussians, in the units a user
// reads them in: positions in world units, scales as log scales (a relative error), rotations per
// component of the unit quaternion (q and -q are the same rotation), opacity after the sigmoid, SH
// coefficients as stored. SH bands a file does not carry count as zeros, so dropping bands shows as
// the error it is.
struct AttributeErrors {
  double position = 0;
  double log_scale = 0;
  double rotation = 0;
  double opacity = 0;
  double sh_dc = 0;
  double sh_rest = 0;
};

struct AttributeComparison {
  bool comparable = false;  // the file has as many Gaussians as the reference: the errors are meaningful
  bool reordered = false;   // matched by nearest mean rather than by index
  size_t reference_gaussians_matched = 0;  // distinct reference Gaussians matched (all of them: one-to-one)
  AttributeErrors max_abs;
};

// Matches `file` to `reference` (see the file comment) and measures the attribute errors.
AttributeComparison compare_attributes(const GaussianScene& reference, const GaussianScene& file);

struct FileRow {
  std::filesystem::path path;
  std::string
      format;  // "spz 4", "sog 2", "ply binary_little_endian 1.0", ... (LoadReport's format and version)
  uint64_t file_bytes = 0;  // a directory's (unbundled SOG) is the sum of its meta.json and images
  size_t gaussians = 0;
  int sh_degree = 0;
  std::vector<double> load_ms;   // one per measured load
  uint64_t load_peak_bytes = 0;  // peak resident memory of the first load, above what was resident before
  AttributeComparison attributes;
  std::vector<ImageDifference> views;  // against the reference's image, one per view

  double bytes_per_gaussian() const { return gaussians ? double(file_bytes) / double(gaussians) : 0; }
  double median_load_ms() const;
  double min_psnr_db() const;  // over the views (+inf: identical at every view)
  double max_abs() const;      // over the views
};

struct Options {
  std::vector<Camera> views;
  std::vector<std::string> view_names;  // one per view, for the tables ("view 0")
  RenderSettings settings;
  int warmup = 1;  // loads discarded before measuring (they fill the page cache)
  int repeat = 5;  // loads measured
};

struct Report {
  std::string reference_name;  // the reference file's name
  std::vector<FileRow> rows;   // the reference first, then the files in the order given
  DeviceInfo device;
  uint64_t validation_messages = 0;
  std::vector<std::string> view_names;  // Options::view_names
  std::string views_label;              // "view 0, view 4 at 960x540"
};

// How the tables name a file: its file name, or for an unbundled SOG's meta.json "DIRECTORY/meta.json".
std::string display_name(const std::filesystem::path& path);

// Loads the reference and every file (`options.warmup + options.repeat` times each), compares their
// attributes and renders each at every view. progress(done, total, what) as it goes. Throws
// SceneError naming a file that cannot be read.
Report measure(Renderer& renderer, const std::filesystem::path& reference,
               const std::vector<std::filesystem::path>& files, const Options& options,
               const std::function<void(int, int, const std::string&)>& progress);
int work_units(size_t files, const Options& options);

std::string text_table(const Report& report);
std::string markdown(const Report& report, const std::string& command);
std::string csv(const Report& report);
// Bytes per Gaussian against the worst PSNR over the views, one point per file, with the Pareto front.
std::string size_psnr_svg(const Report& report);

}  // namespace tilesplat::formats
