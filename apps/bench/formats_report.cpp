#include "formats_report.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>

#include "bench_plot.h"
#include "cli.h"

namespace tilesplat::formats {

namespace fs = std::filesystem;

namespace {

// An error of any magnitude in three significant digits: 0, 0.00244, 1.2e-07.
std::string error_text(double value) {
  if (value == 0) return "0";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", value);
  return buffer;
}

double sigmoid(double x) {
  return 1.0 / (1.0 + std::exp(-x));
}

double mebibytes(uint64_t bytes) {
  return double(bytes) / (1024.0 * 1024.0);
}

// The size of a file; an unbundled SOG is its meta.json and the WebP images beside it, and its size
// is theirs together.
uint64_t file_bytes(const fs::path& path) {
  std::error_code error;
  const auto size = fs::file_size(path, error);
  uint64_t total = error ? 0 : uint64_t(size);
  if (path.filename() != "meta.json") return total;
  const fs::path directory = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  for (const auto& entry : fs::directory_iterator(directory, error))
    if (entry.path().extension() == ".webp" && entry.is_regular_file(error)) total += entry.file_size(error);
  return total;
}

double distance(const float* a, const float* b) {
  double sum = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double d = double(a[axis]) - double(b[axis]);
    sum += d * d;
  }
  return std::sqrt(sum);
}

// Nearest-mean lookup over the reference's positions: a uniform grid of about two Gaussians per cell,
// searched in growing shells of cells around the query until no unsearched cell can hold a nearer mean.
class NearestMean {
 public:
  explicit NearestMean(const std::vector<float>& positions) : positions_(positions) {
    const size_t count = positions.size() / 3;
    for (int axis = 0; axis < 3; ++axis) {
      lo_[axis] = std::numeric_limits<double>::infinity();
      double hi = -lo_[axis];
      for (size_t i = 0; i < count; ++i) {
        lo_[axis] = std::min(lo_[axis], double(positions[3 * i + axis]));
        hi = std::max(hi, double(positions[3 * i + axis]));
      }
      extent_[axis] = count ? hi - lo_[axis] : 0;
    }
    const double volume =
        std::max(extent_[0], 1e-30) * std::max(extent_[1], 1e-30) * std::max(extent_[2], 1e-30);
    cell_ = std::cbrt(2.0 * volume / double(std::max<size_t>(count, 1)));
    const double longest = std::max({extent_[0], extent_[1], extent_[2]});
    cell_ = std::max(cell_, longest / 256.0);  // at most 256 cells an axis
    if (!(cell_ > 0)) cell_ = 1;
    for (int axis = 0; axis < 3; ++axis) cells_[axis] = std::max(1, int(std::ceil(extent_[axis] / cell_)));
    // Counting sort of the Gaussians by cell.
    start_.assign(size_t(cells_[0]) * size_t(cells_[1]) * size_t(cells_[2]) + 1, 0);
    std::vector<uint32_t> cell_of(count);
    for (size_t i = 0; i < count; ++i) {
      cell_of[i] = uint32_t(cell_index(cell_coordinates(&positions[3 * i])));
      ++start_[cell_of[i] + 1];
    }
    for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    members_.resize(count);
    std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < count; ++i) members_[fill[cell_of[i]]++] = uint32_t(i);
  }

  // The reference Gaussians whose means are about as near to `p` as the nearest one: within twice its
  // distance (and a hair past it, for exact ties). A lossy format moves each mean by up to its
  // quantization step, so of two reference means closer together than that, the nearer one need not
  // be the one the file's Gaussian came from; the caller tells them apart by their other attributes.
  std::vector<uint32_t> nearest(const float* p) const {
    const std::array<int, 3> home = cell_coordinates(p);
    std::vector<std::pair<double, uint32_t>> found;  // (distance, index) of every mean searched so far
    double best = std::numeric_limits<double>::infinity();
    const double hair = 1e-9 * std::max({extent_[0], extent_[1], extent_[2], 1e-30});
    const int max_shell = std::max({cells_[0], cells_[1], cells_[2]});
    for (int shell = 0; shell <= max_shell; ++shell) {
      for (int dz = -shell; dz <= shell; ++dz)
        for (int dy = -shell; dy <= shell; ++dy)
          for (int dx = -shell; dx <= shell; ++dx) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != shell)
              continue;  // the shell's surface only
            const std::array<int, 3> c = {home[0] + dx, home[1] + dy, home[2] + dz};
            if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= cells_[0] || c[1] >= cells_[1] ||
                c[2] >= cells_[2])
              continue;
            const size_t cell = cell_index(c);
            for (uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
              const uint32_t i = members_[k];
              const double d = distance(p, &positions_[3 * size_t(i)]);
              best = std::min(best, d);
              found.emplace_back(d, i);
            }
          }
      // A mean in a cell past this shell is at least `shell` cells away along some axis.
      if (2 * best + hair <= double(shell) * cell_) break;
    }
    std::vector<uint32_t> near;
    for (const auto& [d, i] : found)
      if (d <= 2 * best + hair) near.push_back(i);
    std::sort(near.begin(), near.end());
    return near;
  }

 private:
  std::array<int, 3> cell_coordinates(const float* p) const {
    std::array<int, 3> c{};
    for (int axis = 0; axis < 3; ++axis) {
      const double t = std::floor((double(p[axis]) - lo_[axis]) / cell_);
      c[axis] =
          int(std::clamp(t, 0.0, double(cells_[axis] - 1)));  // a query outside the box starts at its edge
    }
    return c;
  }
  size_t cell_index(const std::array<int, 3>& c) const {
    return (size_t(c[2]) * size_t(cells_[1]) + size_t(c[1])) * size_t(cells_[0]) + size_t(c[0]);
  }

  const std::vector<float>& positions_;
  double lo_[3] = {0, 0, 0};
  double extent_[3] = {0, 0, 0};
  double cell_ = 1;
  int cells_[3] = {1, 1, 1};
  std::vector<uint32_t> start_;    // per cell, its first entry in members_ (and one past the last)
  std::vector<uint32_t> members_;  // Gaussian indices, grouped by cell
};

// SH coefficient k (0: DC) of colour channel c of Gaussian i, 0 beyond the scene's degree.
double sh_value(const GaussianScene& scene, size_t i, int k, int c) {
  if (k >= scene.sh_coefficients()) return 0;
  return scene.sh[(i * size_t(scene.sh_coefficients()) + size_t(k)) * 3 + size_t(c)];
}

// How different two Gaussians look apart from their means: activated opacity, log scales, rotation
// (sign-free) and base colour, each in its own units, summed. Used only to choose among near means.
double appearance_distance(const GaussianScene& a, size_t i, const GaussianScene& b, size_t j) {
  double sum = std::abs(sigmoid(a.opacity_logits[i]) - sigmoid(b.opacity_logits[j]));
  double dot = 0;
  for (int k = 0; k < 4; ++k) dot += double(a.rotations[4 * i + k]) * double(b.rotations[4 * j + k]);
  sum += 1 - std::min(1.0, std::abs(dot));
  for (int k = 0; k < 3; ++k) {
    sum += std::abs(double(a.log_scales[3 * i + k]) - double(b.log_scales[3 * j + k]));
    sum += std::abs(sh_value(a, i, 0, k) - sh_value(b, j, 0, k));
  }
  return sum;
}

void accumulate_errors(const GaussianScene& reference, size_t r, const GaussianScene& file, size_t f,
                       AttributeErrors& errors) {
  auto widen = [](double& worst, double a, double b) { worst = std::max(worst, std::abs(a - b)); };
  for (int axis = 0; axis < 3; ++axis) {
    widen(errors.position, reference.positions[3 * r + axis], file.positions[3 * f + axis]);
    widen(errors.log_scale, reference.log_scales[3 * r + axis], file.log_scales[3 * f + axis]);
  }
  double dot = 0;
  for (int k = 0; k < 4; ++k)
    dot += double(reference.rotations[4 * r + k]) * double(file.rotations[4 * f + k]);
  const double sign = dot < 0 ? -1.0 : 1.0;  // q and -q are the same rotation
  for (int k = 0; k < 4; ++k)
    widen(errors.rotation, reference.rotations[4 * r + k], sign * file.rotations[4 * f + k]);
  widen(errors.opacity, sigmoid(reference.opacity_logits[r]), sigmoid(file.opacity_logits[f]));
  const int coefficients = std::max(reference.sh_coefficients(), file.sh_coefficients());
  for (int k = 0; k < coefficients; ++k)
    for (int c = 0; c < 3; ++c)
      widen(k == 0 ? errors.sh_dc : errors.sh_rest, sh_value(reference, r, k, c), sh_value(file, f, k, c));
}

}  // namespace

AttributeComparison compare_attributes(const GaussianScene& reference, const GaussianScene& file) {
  AttributeComparison result;
  const size_t count = reference.size();
  if (file.size() != count || count == 0) return result;
  result.comparable = true;

  // By nearest Gaussian (its mean, then its looks among means about as near), then by index: the index order
  // is kept unless the nearest means fit clearly better (a reordering file leaves index pairs scene-sized
  // apart; a lossy one that keeps the order leaves them as close as its quantization, which nearest matching
  // cannot beat by much).
  const NearestMean lookup(reference.positions);
  std::vector<size_t> nearest(count);
  std::vector<double> by_nearest(count), by_index(count);
  for (size_t i = 0; i < count; ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (const uint32_t r : lookup.nearest(&file.positions[3 * i])) {
      const double looks = appearance_distance(reference, r, file, i);
      if (looks < best) {
        best = looks;
        nearest[i] = r;
      }
    }
    by_nearest[i] = distance(&reference.positions[3 * nearest[i]], &file.positions[3 * i]);
    by_index[i] = distance(&reference.positions[3 * i], &file.positions[3 * i]);
  }
  result.reordered = cli::median(by_index) > 2.0 * cli::median(by_nearest);

  std::vector<bool> reached(count, false);
  for (size_t i = 0; i < count; ++i) {
    const size_t r = result.reordered ? nearest[i] : i;
    reached[r] = true;
    accumulate_errors(reference, r, file, i, result.max_abs);
  }
  result.reference_gaussians_matched = size_t(std::count(reached.begin(), reached.end(), true));
  return result;
}

std::string display_name(const fs::path& path) {
  if (path.filename() != "meta.json" || path.parent_path().filename().empty())
    return path.filename().string();
  return (path.parent_path().filename() / path.filename()).generic_string();
}

double FileRow::median_load_ms() const {
  return cli::median(load_ms);
}

double FileRow::min_psnr_db() const {
  double worst = std::numeric_limits<double>::infinity();
  for (const ImageDifference& view : views) worst = std::min(worst, view.psnr_db);
  return worst;
}

double FileRow::max_abs() const {
  double worst = 0;
  for (const ImageDifference& view : views) worst = std::max(worst, view.max_abs);
  return worst;
}

int work_units(size_t files, const Options& options) {
  return int(files + 1) * (options.warmup + options.repeat + int(options.views.size()));
}

Report measure(Renderer& renderer, const fs::path& reference, const std::vector<fs::path>& files,
               const Options& options, const std::function<void(int, int, const std::string&)>& progress) {
  Report report;
  report.reference_name = reference.filename().string();
  report.device = renderer.device_info();
  report.view_names = options.view_names;
  const int total = work_units(files.size(), options);
  int done = 0;

  std::vector<RenderImage> reference_images;
  GaussianScene reference_scene;
  std::vector<fs::path> paths = {reference};
  paths.insert(paths.end(), files.begin(), files.end());
  for (size_t p = 0; p < paths.size(); ++p) {
    FileRow row;
    row.path = paths[p];
    row.file_bytes = file_bytes(row.path);
    const std::string name = display_name(row.path);
    GaussianScene scene;
    LoadReport load_report;
    for (int load = 0; load < options.warmup + options.repeat; ++load) {
      const bool measured = load >= options.warmup;
      scene = {};  // each load starts from nothing, as a first load would
      if (measured && row.load_ms.empty()) cli::reset_peak_memory();
      const uint64_t resident = cli::resident_memory_bytes();
      load_report = {};
      const auto start = std::chrono::steady_clock::now();
      scene = load_scene(row.path, {}, &load_report);
      const auto stop = std::chrono::steady_clock::now();
      if (measured) {
        if (row.load_ms.empty()) {
          const uint64_t peak = cli::peak_memory_bytes();
          row.load_peak_bytes = peak > resident ? peak - resident : 0;
        }
        row.load_ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
      }
      progress(++done, total, name + ": load");
    }
    row.format = load_report.format + (load_report.version.empty() ? "" : " " + load_report.version);
    row.gaussians = scene.size();
    row.sh_degree = scene.sh_degree;
    if (p == 0) reference_scene = std::move(scene);
    const GaussianScene& measured = p == 0 ? reference_scene : scene;
    row.attributes = compare_attributes(reference_scene, measured);

    renderer.set_scene(measured);
    for (size_t v = 0; v < options.views.size(); ++v) {
      RenderImage image = renderer.render(options.views[v], options.settings);
      if (p == 0) {
        reference_images.push_back(std::move(image));
        row.views.push_back(compare_images(reference_images[v], reference_images[v]));
      } else {
        row.views.push_back(compare_images(reference_images[v], image));
      }
      progress(++done, total, name + ": " + options.view_names[v]);
    }
    report.rows.push_back(std::move(row));
  }
  report.validation_messages = renderer.validation_messages();
  return report;
}

namespace {

std::string order_text(const AttributeComparison& a, size_t gaussians) {
  if (!a.comparable) return "count differs";
  if (!a.reordered) return "kept";
  std::string text = "reordered";
  if (a.reference_gaussians_matched != gaussians)
    text += " (" + std::to_string(gaussians - a.reference_gaussians_matched) + " unmatched)";
  return text;
}

// The columns of both tables, as text cells per row.
struct Columns {
  std::vector<std::string> headers;
  std::vector<std::vector<std::string>> rows;
};

Columns size_columns(const Report& report) {
  Columns table;
  table.headers = {"file",    "format",  "Gaussians", "SH",      "size MiB",
                   "bytes/G", "load ms", "x ref",     "peak MiB"};
  const double reference_ms = report.rows.front().median_load_ms();
  for (const FileRow& row : report.rows) {
    const double ms = row.median_load_ms();
    table.rows.push_back({display_name(row.path), row.format, std::to_string(row.gaussians),
                          std::to_string(row.sh_degree), cli::format_number(mebibytes(row.file_bytes), 2),
                          cli::format_number(row.bytes_per_gaussian(), 1),
                          cli::format_number(ms, ms < 10 ? 2 : 1),
                          reference_ms > 0 ? cli::format_number(ms / reference_ms, 2) : "-",
                          cli::format_number(mebibytes(row.load_peak_bytes), 1)});
  }
  return table;
}

Columns fidelity_columns(const Report& report) {
  Columns table;
  table.headers = {"file", "order", "position", "log scale", "rotation", "opacity", "SH DC", "SH rest"};
  for (size_t v = 0; v < report.view_names.size(); ++v) {
    table.headers.push_back("PSNR " + report.view_names[v] + " dB");
    table.headers.push_back("max abs " + report.view_names[v]);
  }
  for (const FileRow& row : report.rows) {
    const AttributeComparison& a = row.attributes;
    std::vector<std::string> cells = {display_name(row.path), order_text(a, row.gaussians)};
    for (double value : {a.max_abs.position, a.max_abs.log_scale, a.max_abs.rotation, a.max_abs.opacity,
                         a.max_abs.sh_dc, a.max_abs.sh_rest})
      cells.push_back(a.comparable ? error_text(value) : "-");
    for (const ImageDifference& view : row.views) {
      cells.push_back(cli::format_number(view.psnr_db, 2));
      cells.push_back(error_text(view.max_abs));
    }
    table.rows.push_back(std::move(cells));
  }
  return table;
}

std::string aligned(const Columns& table) {
  std::vector<size_t> widths(table.headers.size(), 0);
  for (size_t c = 0; c < widths.size(); ++c) {
    widths[c] = table.headers[c].size();
    for (const auto& row : table.rows) widths[c] = std::max(widths[c], row[c].size());
  }
  auto line = [&](const std::vector<std::string>& cells) {
    std::string out;
    for (size_t c = 0; c < cells.size(); ++c) {
      const size_t pad = widths[c] - cells[c].size();
      // The file name reads left-aligned, the numbers right-aligned.
      out += c == 0 ? cells[c] + std::string(pad, ' ') : std::string(pad, ' ') + cells[c];
      out += c + 1 < cells.size() ? "  " : "\n";
    }
    return out;
  };
  std::string out = line(table.headers);
  for (const auto& row : table.rows) out += line(row);
  return out;
}

std::string markdown_table(const Columns& table) {
  std::string out = "|";
  for (const auto& header : table.headers) out += " " + header + " |";
  out += "\n|---|";
  for (size_t c = 1; c < table.headers.size(); ++c) out += "---:|";
  out += '\n';
  for (const auto& row : table.rows) {
    out += "|";
    for (const auto& cell : row) {
      out += ' ';
      out += cell;
      out += " |";
    }
    out += '\n';
  }
  return out;
}

}  // namespace

std::string text_table(const Report& report) {
  return "size and loading (load ms: median of " + std::to_string(report.rows.front().load_ms.size()) +
         " loads; x ref: against " + report.reference_name + ")\n" + aligned(size_columns(report)) +
         "\nfidelity against " + report.reference_name +
         " (attributes: max abs; images: " + report.views_label + ")\n" + aligned(fidelity_columns(report));
}

std::string markdown(const Report& report, const std::string& command) {
  std::string out = "# Format costs: " + report.reference_name + "\n\n";
  out += "Device: " + report.device.name + " (driver " + report.device.driver + "). Command: `" + command +
         "`.\n\n";
  out += "Size and loading: load ms is the median of " + std::to_string(report.rows.front().load_ms.size()) +
         " loads (page cache warm), x ref the ratio to the reference's; peak MiB is the resident memory the "
         "first "
         "load added at its peak.\n\n";
  out += markdown_table(size_columns(report));
  out +=
      "\nFidelity against " + report.reference_name +
      ": attributes as the largest absolute difference over matched Gaussians (position in world units, "
      "log scale, quaternion component, opacity after the sigmoid, SH coefficients; bands a file lacks count "
      "as zeros); images (" +
      report.views_label + ") as PSNR over RGB and the largest absolute difference.\n\n";
  out += markdown_table(fidelity_columns(report));
  return out;
}

std::string csv(const Report& report) {
  std::string out =
      "device,reference,file,format,gaussians,sh_degree,file_bytes,bytes_per_gaussian,load_ms_median,load_"
      "peak_bytes,"
      "order,err_position,err_log_scale,err_rotation,err_opacity,err_sh_dc,err_sh_rest,view,psnr_db,max_"
      "abs\n";
  for (const FileRow& row : report.rows) {
    const AttributeComparison& a = row.attributes;
    std::string prefix =
        cli::csv_field(report.device.name) + "," + cli::csv_field(report.reference_name) + "," +
        cli::csv_field(display_name(row.path)) + "," + cli::csv_field(row.format) + "," +
        std::to_string(row.gaussians) + "," + std::to_string(row.sh_degree) + "," +
        std::to_string(row.file_bytes) + "," + cli::format_number(row.bytes_per_gaussian(), 3) + "," +
        cli::format_number(row.median_load_ms(), 3) + "," + std::to_string(row.load_peak_bytes) + "," +
        cli::csv_field(order_text(a, row.gaussians));
    for (double value : {a.max_abs.position, a.max_abs.log_scale, a.max_abs.rotation, a.max_abs.opacity,
                         a.max_abs.sh_dc, a.max_abs.sh_rest}) {
      prefix += ',';
      if (a.comparable) prefix += error_text(value);
    }
    for (size_t v = 0; v < row.views.size(); ++v)
      out += prefix + "," + cli::csv_field(report.view_names[v]) + "," +
             cli::format_number(row.views[v].psnr_db, 4) + "," + error_text(row.views[v].max_abs) + "\n";
  }
  return out;
}

std::string size_psnr_svg(const Report& report) {
  plot::ScatterChart chart;
  chart.title = "What each format costs: " + report.reference_name;
  chart.subtitle =
      report.device.name + "; worst PSNR over " + report.views_label + " against the reference's image";
  chart.x_label = "bytes per Gaussian (file size / Gaussians)";
  chart.y_label = "worst PSNR over the views (dB)";
  chart.y_higher_is_better = true;
  size_t color = 0;
  for (const FileRow& row : report.rows)
    chart.points.push_back({display_name(row.path) + " (" + row.format + ")", row.bytes_per_gaussian(),
                            row.min_psnr_db(), color++});
  return plot::scatter_svg(chart);
}

}  // namespace tilesplat::formats
