#include "scaling_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "bench_plot.h"
#include "cli.h"

namespace tilesplat::scaling {

namespace {

std::string fixed(double value, int decimals) {
  return cli::format_fixed(value, decimals);
}
constexpr double kMiB = 1024.0 * 1024.0;

// Pass names in frame order over all points.
std::vector<std::string> pass_names(const std::vector<Point>& points) {
  std::vector<std::string> names;
  for (const Point& point : points)
    for (const PassTiming& pass : point.passes)
      if (std::find(names.begin(), names.end(), pass.name) == names.end()) names.push_back(pass.name);
  return names;
}

double pass_ms(const Point& point, const std::string& name) {
  for (const PassTiming& pass : point.passes)
    if (pass.name == name) return pass.gpu_ms;
  return 0;
}

std::string size_text(const Size& size) {
  return cli::format_size(size.width, size.height);
}

// Solves the normal equations of the columns in `use` (Gaussian elimination with partial pivoting);
// false where they are singular.
bool solve_subset(const std::vector<std::array<double, 4>>& x, const std::vector<double>& y, unsigned use,
                  std::array<double, 4>& out) {
  std::vector<int> cols;
  for (int c = 0; c < 4; ++c)
    if (use & (1u << c)) cols.push_back(c);
  const size_t n = cols.size();
  std::vector<std::vector<double>> a(n, std::vector<double>(n + 1, 0.0));
  for (size_t r = 0; r < x.size(); ++r)
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = 0; j < n; ++j) a[i][j] += x[r][cols[i]] * x[r][cols[j]];
      a[i][n] += x[r][cols[i]] * y[r];
    }
  for (size_t i = 0; i < n; ++i) {
    size_t pivot = i;
    for (size_t k = i + 1; k < n; ++k)
      if (std::abs(a[k][i]) > std::abs(a[pivot][i])) pivot = k;
    if (!(std::abs(a[pivot][i]) > 1e-12 * std::max(1.0, std::abs(a[i][i])))) return false;
    std::swap(a[i], a[pivot]);
    for (size_t k = 0; k < n; ++k) {
      if (k == i) continue;
      const double factor = a[k][i] / a[i][i];
      for (size_t j = i; j <= n; ++j) a[k][j] -= factor * a[i][j];
    }
  }
  out = {0, 0, 0, 0};
  for (size_t i = 0; i < n; ++i) out[cols[i]] = a[i][n] / a[i][i];
  return true;
}

// Non-negative least squares with four unknowns: the best of the unconstrained fits over every
// subset of the columns whose coefficients are all >= 0 (16 small solves, exact).
Fit fit_one(const std::string& what, const std::vector<std::array<double, 4>>& x,
            const std::vector<double>& y) {
  Fit best;
  best.what = what;
  double best_residual = std::numeric_limits<double>::infinity();
  for (unsigned use = 1; use < 16; ++use) {
    std::array<double, 4> c{};
    if (!solve_subset(x, y, use, c)) continue;
    if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[3] < 0) continue;
    double residual = 0;
    for (size_t r = 0; r < x.size(); ++r) {
      const double e = y[r] - (c[0] * x[r][0] + c[1] * x[r][1] + c[2] * x[r][2] + c[3] * x[r][3]);
      residual += e * e;
    }
    if (residual < best_residual) {
      best_residual = residual;
      best.per_gaussian = c[0];
      best.per_pair = c[1];
      best.per_pixel = c[2];
      best.fixed = c[3];
    }
  }
  double mean = 0;
  for (double v : y) mean += v;
  mean /= double(std::max<size_t>(1, y.size()));
  double total = 0;
  for (double v : y) total += (v - mean) * (v - mean);
  best.r2 = total > 0 && std::isfinite(best_residual) ? 1.0 - best_residual / total : 1.0;
  return best;
}

// The size whose pixel count is nearest 1920x1080 (the reference size of the charts).
Size reference_size(const std::vector<Point>& points) {
  Size best = points.front().size;
  const double target = 1920.0 * 1080.0;
  for (const Point& p : points)
    if (std::abs(double(p.size.pixels()) - target) < std::abs(double(best.pixels()) - target)) best = p.size;
  return best;
}

std::string largest_scene(const std::vector<Point>& points) {
  const Point* largest = &points.front();
  for (const Point& p : points)
    if (p.gaussians > largest->gaussians) largest = &p;
  return largest->scene;
}

// The fits table (ns per Gaussian, per pair, per pixel; fixed ms) in the text or Markdown layout.
std::vector<std::vector<std::string>> fit_rows(const std::vector<Fit>& fits) {
  std::vector<std::vector<std::string>> rows;
  for (const Fit& f : fits) {
    if (f.what == "device memory") {
      rows.push_back({f.what, fixed(f.per_gaussian, 1) + " B", fixed(f.per_pair, 1) + " B",
                      fixed(f.per_pixel, 2) + " B", fixed(f.fixed / kMiB, 1) + " MiB", fixed(f.r2, 3)});
    } else {
      // ms per unit -> ns per unit
      rows.push_back({f.what, fixed(f.per_gaussian * 1e6, 1), fixed(f.per_pair * 1e6, 1),
                      fixed(f.per_pixel * 1e6, 2), fixed(f.fixed, 2), fixed(f.r2, 3)});
    }
  }
  return rows;
}

std::string markdown_row(const std::vector<std::string>& cells) {
  std::string out = "|";
  for (const std::string& cell : cells) {
    out += ' ';
    out += cell;
    out += " |";
  }
  return out + "\n";
}

// One line per pass and one for the frame: the median GPU time of the points `chosen` picks, against
// x_of(point), in the order of x.
std::string per_pass_chart(const Run& run, const std::string& title, const std::string& x_label,
                           plot::Scale x_scale, const std::function<bool(const Point&)>& chosen,
                           const std::function<double(const Point&)>& x_of) {
  plot::LineChart chart;
  chart.title = title;
  chart.subtitle = run.device.name;
  chart.x_label = x_label;
  chart.y_label = "median GPU time (ms)";
  chart.x_scale = x_scale;
  chart.y_scale = plot::Scale::kLog10;
  std::vector<std::string> names = pass_names(run.points);
  names.push_back("gpu frame");
  for (size_t i = 0; i < names.size(); ++i) {
    const bool frame = names[i] == "gpu frame";
    plot::LineSeries series{names[i], i, frame ? 1u : 0u, {}};
    for (const Point& p : run.points)
      if (chosen(p)) series.points.emplace_back(x_of(p), frame ? p.frame_ms : pass_ms(p, names[i]));
    std::sort(series.points.begin(), series.points.end());
    chart.series.push_back(std::move(series));
  }
  return plot::line_chart_svg(chart);
}

}  // namespace

GaussianScene tile_scene(const GaussianScene& scene, int copies) {
  if (copies < 1) throw std::invalid_argument("tile_scene: copies must be at least 1");
  const Bounds bounds = compute_bounds(scene);
  const float step_x = float((bounds.max[0] - bounds.min[0]) * 1.05);
  const float step_z = float((bounds.max[2] - bounds.min[2]) * 1.05);
  const int columns = int(std::ceil(std::sqrt(double(copies))));
  GaussianScene tiled;
  tiled.sh_degree = scene.sh_degree;
  const size_t n = scene.size();
  tiled.positions.reserve(3 * n * size_t(copies));
  for (int c = 0; c < copies; ++c) {
    const float dx = step_x * float(c % columns), dz = step_z * float(c / columns);
    for (size_t i = 0; i < n; ++i) {
      tiled.positions.push_back(scene.positions[3 * i] + dx);
      tiled.positions.push_back(scene.positions[3 * i + 1]);
      tiled.positions.push_back(scene.positions[3 * i + 2] + dz);
    }
    tiled.log_scales.insert(tiled.log_scales.end(), scene.log_scales.begin(), scene.log_scales.end());
    tiled.rotations.insert(tiled.rotations.end(), scene.rotations.begin(), scene.rotations.end());
    tiled.opacity_logits.insert(tiled.opacity_logits.end(), scene.opacity_logits.begin(),
                                scene.opacity_logits.end());
    tiled.sh.insert(tiled.sh.end(), scene.sh.begin(), scene.sh.end());
    tiled.normals.insert(tiled.normals.end(), scene.normals.begin(), scene.normals.end());
  }
  return tiled;
}

int work_units(const std::vector<Scene>& scenes, const Options& options) {
  return int(scenes.size() * options.sizes.size()) * (options.warmup + options.repeat);
}

Run measure(const RendererOptions& renderer_options, const std::vector<Scene>& scenes, const Options& options,
            const std::function<void(int, int, const std::string&)>& progress) {
  Run run;
  // One renderer per scene, each holding its scene, so that the points interleave without uploads.
  std::vector<std::unique_ptr<Renderer>> renderers;
  std::vector<std::vector<Camera>> cameras(scenes.size());
  for (size_t s = 0; s < scenes.size(); ++s) {
    renderers.push_back(Renderer::create(renderer_options));
    renderers.back()->set_scene(scenes[s].scene);
    for (const Size& size : options.sizes)
      cameras[s].push_back(orbit_camera(scenes[s].scene, size.width, size.height));
  }
  run.device = renderers.front()->device_info();

  const size_t count = scenes.size() * options.sizes.size();
  std::vector<std::map<std::string, std::vector<double>>> pass_samples(count);
  std::vector<std::vector<double>> frame_samples(count);
  std::vector<std::vector<std::string>> pass_order(count);
  run.points.resize(count);
  const int total = work_units(scenes, options);
  int done = 0;
  for (int frame = 0; frame < options.warmup + options.repeat; ++frame) {
    for (size_t z = 0; z < options.sizes.size(); ++z) {
      for (size_t s = 0; s < scenes.size(); ++s) {
        const size_t k = s * options.sizes.size() + z;
        RenderSettings settings;
        settings.sort = options.sort;
        settings.compositor = options.compositor;
        settings.reuse_lists = false;
        renderers[s]->render(cameras[s][z], settings);
        const FrameStats& stats = renderers[s]->last_frame_stats();
        Point& point = run.points[k];
        if (frame == 0) {
          point.scene = scenes[s].name;
          point.gaussians = scenes[s].scene.size();
          point.size = options.sizes[z];
          point.visible = stats.visible;
          point.pairs = stats.intersections;
          point.device_bytes = stats.device_bytes;
        }
        if (frame >= options.warmup) {
          frame_samples[k].push_back(stats.gpu_ms);
          for (const PassTiming& pass : stats.passes) {
            pass_samples[k][pass.name].push_back(pass.gpu_ms);
            auto& order = pass_order[k];
            if (std::find(order.begin(), order.end(), pass.name) == order.end()) order.push_back(pass.name);
          }
        }
        progress(++done, total, scenes[s].name + " " + size_text(options.sizes[z]));
      }
    }
  }
  for (size_t k = 0; k < count; ++k) {
    run.points[k].frame_ms = cli::median(frame_samples[k]);
    for (const std::string& name : pass_order[k])
      run.points[k].passes.push_back({name, cli::median(pass_samples[k][name])});
  }
  for (const auto& renderer : renderers) run.validation_messages += renderer->validation_messages();
  return run;
}

std::vector<Fit> fit(const std::vector<Point>& points) {
  std::vector<std::array<double, 4>> x;
  for (const Point& p : points)
    x.push_back({double(p.gaussians), double(p.pairs), double(p.size.pixels()), 1.0});
  std::vector<Fit> fits;
  for (const std::string& name : pass_names(points)) {
    std::vector<double> y;
    for (const Point& p : points) y.push_back(pass_ms(p, name));
    fits.push_back(fit_one(name, x, y));
  }
  std::vector<double> frame, memory;
  for (const Point& p : points) {
    frame.push_back(p.frame_ms);
    memory.push_back(double(p.device_bytes));
  }
  fits.push_back(fit_one("gpu frame", x, frame));
  fits.push_back(fit_one("device memory", x, memory));
  return fits;
}

std::string dominant_pass(const Point& point) {
  const PassTiming* top = nullptr;
  for (const PassTiming& pass : point.passes)
    if (!top || pass.gpu_ms > top->gpu_ms) top = &pass;
  return top ? top->name : "";
}

std::string text_report(const Run& run, const std::vector<Fit>& fits) {
  const std::vector<std::string> passes = pass_names(run.points);
  std::string out = "  scene                                    Gaussians       size      pairs   frame ms";
  for (const auto& name : passes)
    out += " " + std::string(std::max<size_t>(0, 13 - std::min<size_t>(13, name.size())), ' ') + name;
  out += "  dominant        MiB\n";
  for (const Point& p : run.points) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-39s %10s %10s %10s %10s", p.scene.c_str(),
                  cli::format_number(double(p.gaussians), 0).c_str(), size_text(p.size).c_str(),
                  cli::format_number(double(p.pairs), 0).c_str(), fixed(p.frame_ms, 1).c_str());
    out += line;
    for (const auto& name : passes) {
      std::snprintf(line, sizeof line, " %13s", fixed(pass_ms(p, name), 1).c_str());
      out += line;
    }
    std::snprintf(line, sizeof line, "  %-12s %8s\n", dominant_pass(p).c_str(),
                  fixed(double(p.device_bytes) / kMiB, 1).c_str());
    out += line;
  }
  out += "\n  fit over all points, every coefficient >= 0: time = a Gaussians + b pairs + c pixels + fixed\n";
  out += "  what                 ns/Gaussian     ns/pair    ns/pixel    fixed ms     R^2\n";
  for (const auto& row : fit_rows(fits)) {
    char line[200];
    std::snprintf(line, sizeof line, "  %-18s %13s %11s %11s %11s %7s\n", row[0].c_str(), row[1].c_str(),
                  row[2].c_str(), row[3].c_str(), row[4].c_str(), row[5].c_str());
    out += line;
  }
  return out;
}

std::string markdown(const Run& run, const std::vector<Fit>& fits, const std::string& command) {
  const std::vector<std::string> passes = pass_names(run.points);
  std::string out = "# How the frame's cost grows\n\n";
  out +=
      "Device: " + run.device.name + " (driver " + run.device.driver + "). Command: `" + command + "`.\n\n";
  out += "GPU ms per pass (median over the repeats), each scene from the orbit camera that frames it.\n\n";
  std::vector<std::string> header = {"scene", "Gaussians", "size", "pairs"};
  for (const auto& name : passes) header.push_back(name);
  for (const char* tail : {"frame ms", "dominant", "device MiB"}) header.push_back(tail);
  out += markdown_row(header);
  std::string rule = "|---|---:|---|---:|";
  for (size_t i = 0; i < passes.size(); ++i) rule += "---:|";
  out += rule + "---:|---|---:|\n";
  for (const Point& p : run.points) {
    std::vector<std::string> cells = {p.scene, cli::format_number(double(p.gaussians), 0), size_text(p.size),
                                      cli::format_number(double(p.pairs), 0)};
    for (const auto& name : passes) cells.push_back(fixed(pass_ms(p, name), 1));
    cells.push_back(fixed(p.frame_ms, 1));
    cells.push_back(dominant_pass(p));
    cells.push_back(fixed(double(p.device_bytes) / kMiB, 1));
    out += markdown_row(cells);
  }
  out +=
      "\nNon-negative least-squares fit over all points: time = a Gaussians + b pairs + c pixels + fixed "
      "(device memory likewise, in bytes).\n\n";
  out += markdown_row({"what", "per Gaussian (ns)", "per pair (ns)", "per pixel (ns)", "fixed (ms)", "R²"});
  out += "|---|---:|---:|---:|---:|---:|\n";
  for (const auto& row : fit_rows(fits)) out += markdown_row(row);
  return out;
}

std::string csv(const Run& run) {
  std::string out = "device,scene,gaussians,width,height,pairs,visible,metric,value\n";
  for (const Point& p : run.points) {
    const std::string prefix = cli::csv_field(run.device.name) + "," + cli::csv_field(p.scene) + "," +
                               std::to_string(p.gaussians) + "," + std::to_string(p.size.width) + "," +
                               std::to_string(p.size.height) + "," + std::to_string(p.pairs) + "," +
                               std::to_string(p.visible) + ",";
    for (const PassTiming& pass : p.passes)
      out += prefix + cli::csv_field(pass.name) + "_ms," + fixed(pass.gpu_ms, 4) + "\n";
    out += prefix + "frame_ms," + fixed(p.frame_ms, 4) + "\n";
    out += prefix + "device_mib," + fixed(double(p.device_bytes) / kMiB, 3) + "\n";
  }
  return out;
}

std::string svg_time_vs_gaussians(const Run& run) {
  const Size size = reference_size(run.points);
  return per_pass_chart(
      run, "GPU time per pass against Gaussian count, " + size_text(size), "Gaussians", plot::Scale::kLog10,
      [&](const Point& p) { return p.size.width == size.width && p.size.height == size.height; },
      [](const Point& p) { return double(p.gaussians); });
}

std::string svg_time_vs_pixels(const Run& run) {
  const std::string scene = largest_scene(run.points);
  return per_pass_chart(
      run, "GPU time per pass against image size, " + scene, "megapixels", plot::Scale::kLog2,
      [&](const Point& p) { return p.scene == scene; },
      [](const Point& p) { return double(p.size.pixels()) / 1e6; });
}

std::string svg_memory(const Run& run) {
  plot::LineChart chart;
  chart.title = "Device memory against Gaussian count, per image size";
  chart.subtitle = run.device.name;
  chart.x_label = "Gaussians";
  chart.y_label = "device memory (MiB)";
  chart.x_scale = plot::Scale::kLog10;
  chart.y_scale = plot::Scale::kLog10;
  std::vector<Size> sizes;
  for (const Point& p : run.points)
    if (std::none_of(sizes.begin(), sizes.end(),
                     [&](const Size& s) { return s.width == p.size.width && s.height == p.size.height; }))
      sizes.push_back(p.size);
  for (size_t i = 0; i < sizes.size(); ++i) {
    plot::LineSeries series{size_text(sizes[i]), i, 0, {}};
    for (const Point& p : run.points)
      if (p.size.width == sizes[i].width && p.size.height == sizes[i].height)
        series.points.emplace_back(double(p.gaussians), double(p.device_bytes) / kMiB);
    std::sort(series.points.begin(), series.points.end());
    chart.series.push_back(std::move(series));
  }
  return plot::line_chart_svg(chart);
}

}  // namespace tilesplat::scaling
