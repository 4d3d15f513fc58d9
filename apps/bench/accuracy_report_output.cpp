// The accuracy report's outputs (tilesplat-bench --accuracy): the text table, markdown, CSV and charts of
// the SceneReports that accuracy_report.cpp measures.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "accuracy_report.h"
#include "bench_plot.h"
#include "cli.h"

namespace tilesplat::accuracy {

// The PSNR against the sorted compositor's image, "-" for the sorted compositor's own rows.
std::string psnr_vs_sorted(const ModeResult& m) {
  return std::isnan(m.psnr_vs_sorted_db) ? "-" : cli::format_number(m.psnr_vs_sorted_db, 2);
}
std::string time_vs_sorted(const ModeResult& m) {
  return std::isnan(m.psnr_vs_sorted_db) || m.sorted_frame_ms <= 0
             ? "-"
             : cli::format_number(m.frame_ms / m.sorted_frame_ms, 2) + "x";
}
std::string psnr_vs_rule(const ModeResult& m) {
  return std::isnan(m.psnr_vs_rule_db) ? "-" : cli::format_number(m.psnr_vs_rule_db, 2);
}

std::string psnr_vs_ray_order(const ModeResult& m) {
  return std::isnan(m.psnr_vs_ray_order_db) ? "-" : cli::format_number(m.psnr_vs_ray_order_db, 2);
}

std::string text_table(const SceneReport& report) {
  std::string text =
      "  " + report.scene + ", " + report.description + ", " + report.views + "; float64 reference on the " +
      to_string(report.path) + ": " + cli::format_number(100.0 * report.reference_flicker, 3) +
      "% flicker, " + cli::format_number(100.0 * report.reference_pops, 3) + "% pops, " +
      cli::format_number(100.0 * report.reference_warp_pops, 3) + "% warped pops; turned " +
      cli::format_number(report.consistency_angle, 3) +
      " rad: " + cli::format_number(100.0 * report.reference_inconsistency, 3) + "% inconsistent" +
      (std::isnan(report.exact_order_inconsistency)
           ? std::string()
           : " (in the exact ray order " + cli::format_number(100.0 * report.exact_order_inconsistency, 3) +
                 "%)") +
      "\n";
  char line[512];
  std::snprintf(line, sizeof(line), "  %-58s %10s %8s %9s %8s %9s %10s %9s %9s %8s %8s %9s %8s %9s %8s %9s\n",
                "mode", "GPU ms", "vs ref", "PSNR dB", "SSIM", "max abs", "pairs", "flicker%", "excess",
                "pops%", "warp%", "incons%", "vs ray", "vs tiles", "t/tiles", "vs rule");
  text += line;
  const double reference_ms = report.modes.empty() ? 0 : report.modes.front().frame_ms;
  for (const auto& m : report.modes) {
    std::snprintf(
        line, sizeof(line), "  %-58s %10s %7sx %9s %8s %9s %10llu %9s %9s %8s %8s %9s %8s %9s %8s %9s\n",
        m.name.c_str(), cli::format_number(m.frame_ms, 2).c_str(),
        cli::format_number(reference_ms > 0 ? m.frame_ms / reference_ms : 0, 2).c_str(),
        cli::format_number(m.psnr_db, 2).c_str(), cli::format_number(m.ssim, 5).c_str(),
        cli::format_number(m.max_abs, 4).c_str(), static_cast<unsigned long long>(m.intersections),
        cli::format_number(100.0 * m.flicker, 3).c_str(), cli::format_number(m.excess, 5).c_str(),
        cli::format_number(100.0 * m.pops, 3).c_str(), cli::format_number(100.0 * m.warp_pops, 3).c_str(),
        cli::format_number(100.0 * m.inconsistency, 3).c_str(), psnr_vs_ray_order(m).c_str(),
        psnr_vs_sorted(m).c_str(), time_vs_sorted(m).c_str(), psnr_vs_rule(m).c_str());
    text += line;
  }
  return text;
}

std::string markdown(const std::vector<SceneReport>& reports, const DeviceInfo& device,
                     const std::string& command) {
  std::string md =
      "Device: " + device.name + " (" + device.driver + "). Command:\n\n```\n" + command + "\n```\n";
  md +=
      "\nErrors are measured on the trained display values (sRGB-encoded, peak 1), as renders are compared "
      "with "
      "photographs (docs/colour.md).\n";
  for (const auto& report : reports) {
    md += "\n### " + report.scene + "\n\n" + report.description + "; " + report.views + ". Popping over a " +
          std::to_string(report.path_frames) + "-frame " + to_string(report.path) + " (step " +
          cli::format_fixed(report.path_step, 4) + "): the float64 reference itself changes " +
          cli::format_number(report.reference_change, 5) + " per frame on average, with " +
          cli::format_number(100.0 * report.reference_flicker, 3) + "% of pixels changing by more than " +
          cli::format_number(kFlickerThreshold, 2) + " (flicker), and " +
          cli::format_number(100.0 * report.reference_pops, 3) +
          "% of pixels popping: their second difference over three frames exceeds that (`popping()`, which "
          "smooth motion cancels). Warped pops: each frame warped onto the next by its rendered depth, "
          "what the motion reveals or hides left out, the share of " +
          std::to_string(kWarpBlock) + "x" + std::to_string(kWarpBlock) + " blocks differing by more than " +
          cli::format_number(kWarpThreshold, 2) + " (`depth_warp_difference()`; the float64 reference: " +
          cli::format_number(100.0 * report.reference_warp_pops, 3) +
          "%). PSNR vs exact ray order: against the float64 reference blending each pixel's splats in the "
          "order of their depth along its ray (`ReferenceOrder::kRayDepth`).";
    if (report.consistency_angle > 0)
      md += " View consistency: the first view and the same camera turned in place by " +
            cli::format_number(report.consistency_angle, 3) + " rad, rendered at " +
            std::to_string(kConsistencyScale) +
            "x its size; the first resampled onto the second and compared over blocks of " +
            std::to_string(kConsistencyBlock) + "x" + std::to_string(kConsistencyBlock) +
            " pixels (`rotation_inconsistency()`): the float64 reference has " +
            cli::format_number(100.0 * report.reference_inconsistency, 3) +
            "% of blocks differing by more than " + cli::format_number(kConsistencyThreshold, 2) +
            " (inconsistent %), and a mean difference of " +
            cli::format_number(report.reference_inconsistency_mean, 6) + "." +
            (std::isnan(report.exact_order_inconsistency)
                 ? std::string()
                 : " In the exact ray order it has " +
                       cli::format_number(100.0 * report.exact_order_inconsistency, 3) + "% (" +
                       cli::format_number(report.exact_order_inconsistency_mean, 6) +
                       "): not 0, since where two splats' ray depths cross within a pixel the blend order "
                       "flips, an edge the turned view's resampling does not reproduce.");
    md += "\n\n";
    md +=
        "| mode | GPU frame ms | vs reference | PSNR dB | SSIM | max abs | pairs | flicker % | excess change "
        "| pops % | warped pops % "
        "| inconsistent % | inconsistency | PSNR vs exact ray order dB | PSNR vs sorted compositor dB | time "
        "vs sorted compositor | PSNR vs own float64 rule dB |\n";
    md += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    const double reference_ms = report.modes.empty() ? 0 : report.modes.front().frame_ms;
    for (const auto& m : report.modes)
      md += "| " + m.name + " | " + cli::format_number(m.frame_ms, 2) + " | " +
            cli::format_number(reference_ms > 0 ? m.frame_ms / reference_ms : 0, 2) + "x | " +
            cli::format_number(m.psnr_db, 2) + " | " + cli::format_number(m.ssim, 5) + " | " +
            cli::format_number(m.max_abs, 4) + " | " + std::to_string(m.intersections) + " | " +
            cli::format_number(100.0 * m.flicker, 3) + " | " + cli::format_number(m.excess, 5) + " | " +
            cli::format_number(100.0 * m.pops, 3) + " | " + cli::format_number(100.0 * m.warp_pops, 3) +
            " | " + cli::format_number(100.0 * m.inconsistency, 3) + " | " +
            cli::format_number(m.inconsistency_mean, 6) + " | " + psnr_vs_ray_order(m) + " | " +
            psnr_vs_sorted(m) + " | " + time_vs_sorted(m) + " | " + psnr_vs_rule(m) + " |\n";
    // Per-pass times: a column per mode would not fit; the passes whose time a mode changes.
    md += "\nPer-pass median GPU ms:\n\n| mode |";
    std::vector<std::string> names;
    for (const auto& m : report.modes)
      for (const auto& p : m.passes)
        if (std::find(names.begin(), names.end(), p.name) == names.end()) names.push_back(p.name);
    for (const auto& name : names) md += " " + name + " |";
    md += "\n|---|";
    for (size_t i = 0; i < names.size(); ++i) md += "---:|";
    md += "\n";
    for (const auto& m : report.modes) {
      md += "| " + m.name + " |";
      for (const auto& name : names) {
        auto it =
            std::find_if(m.passes.begin(), m.passes.end(), [&](const PassTime& p) { return p.name == name; });
        md += ' ';
        md += it == m.passes.end() ? std::string("-") : cli::format_number(it->ms, 2);
        md += " |";
      }
      md += "\n";
    }
  }
  return md;
}

std::string csv(const std::vector<SceneReport>& reports, const DeviceInfo& device) {
  std::string out =
      "device,scene,mode,gpu_frame_ms,psnr_db,ssim,max_abs,intersections,frame_change,flicker_fraction,"
      "excess_change,pop_fraction,pop_mean,inconsistent_fraction,inconsistency_mean,passes,psnr_vs_sorted_db,"
      "psnr_vs_rule_db,warp_pop_fraction,warp_pop_mean,psnr_vs_ray_order_db\n";
  for (const auto& report : reports)
    for (const auto& m : report.modes) {
      std::string passes;
      for (const auto& p : m.passes)
        passes += (passes.empty() ? "" : ";") + p.name + "=" + cli::format_number(p.ms, 4);
      out += cli::csv_field(device.name) + "," + cli::csv_field(report.scene) + "," + cli::csv_field(m.name) +
             "," + cli::format_number(m.frame_ms, 4) + "," + cli::format_number(m.psnr_db, 4) + "," +
             cli::format_number(m.ssim, 6) + "," + cli::format_number(m.max_abs, 6) + "," +
             std::to_string(m.intersections) + "," + cli::format_number(m.frame_change, 6) + "," +
             cli::format_number(m.flicker, 6) + "," + cli::format_number(m.excess, 6) + "," +
             cli::format_number(m.pops, 6) + "," + cli::format_number(m.pop_mean, 6) + "," +
             cli::format_number(m.inconsistency, 6) + "," + cli::format_number(m.inconsistency_mean, 6) +
             "," + cli::csv_field(passes) + "," +
             (std::isnan(m.psnr_vs_sorted_db) ? std::string() : cli::format_number(m.psnr_vs_sorted_db, 4)) +
             "," +
             (std::isnan(m.psnr_vs_rule_db) ? std::string() : cli::format_number(m.psnr_vs_rule_db, 4)) +
             "," + cli::format_number(m.warp_pops, 6) + "," + cli::format_number(m.warp_mean, 6) + "," +
             (std::isnan(m.psnr_vs_ray_order_db) ? std::string()
                                                 : cli::format_number(m.psnr_vs_ray_order_db, 4)) +
             "\n";
    }
  return out;
}

std::string consistency_svg(const SceneReport& report, const DeviceInfo& device) {
  plot::ScatterChart chart;
  chart.title = "View consistency against time: " + report.scene;
  chart.subtitle = report.description + ", turned in place by " +
                   cli::format_number(report.consistency_angle, 3) + " rad; float64 reference " +
                   cli::format_number(100.0 * report.reference_inconsistency, 3) + "%" +
                   (std::isnan(report.exact_order_inconsistency)
                        ? std::string()
                        : ", in exact ray order " +
                              cli::format_number(100.0 * report.exact_order_inconsistency, 3) + "%") +
                   "; " + device.name;
  chart.x_label = "median GPU frame time (ms, log scale)";
  chart.x_scale = plot::Scale::kLog10;
  chart.y_label = "blocks inconsistent under the turn (%)";
  chart.y_higher_is_better = false;
  for (size_t i = 0; i < report.modes.size(); ++i) {
    const auto& m = report.modes[i];
    chart.points.push_back({m.name, m.frame_ms, 100.0 * m.inconsistency, i});
  }
  return plot::scatter_svg(chart);
}

std::string pareto_svg(const SceneReport& report, const DeviceInfo& device) {
  plot::ScatterChart chart;
  chart.title = "Accuracy against time: " + report.scene;
  chart.subtitle = report.description + ", " + report.views + "; " + device.name;
  chart.x_label = "median GPU frame time (ms, log scale)";
  chart.x_scale = plot::Scale::kLog10;  // the re-sorting modes cost tens of times the others
  chart.y_label = "PSNR against the float64 reference (dB)";
  chart.y_higher_is_better = true;
  for (size_t i = 0; i < report.modes.size(); ++i) {
    const auto& m = report.modes[i];
    chart.points.push_back({m.name, m.frame_ms, m.psnr_db, i});
  }
  return plot::scatter_svg(chart);
}

std::string popping_svg(const SceneReport& report, const DeviceInfo& device) {
  plot::LineChart chart;
  chart.title = "Popping along the path: " + report.scene;
  chart.subtitle = report.description + ", " + std::to_string(report.path_frames) + "-frame " +
                   to_string(report.path) + " (step " + cli::format_fixed(report.path_step, 4) +
                   "), each frame warped onto the next by its depth; " + device.name;
  chart.x_label = "frame pair along the path";
  chart.y_label = "blocks differing after the warp (%)";
  auto series = [](const std::string& label, const std::vector<double>& per_step, size_t color, size_t dash) {
    plot::LineSeries line{label, color, dash, {}};
    for (size_t i = 0; i < per_step.size(); ++i) line.points.push_back({double(i + 1), 100.0 * per_step[i]});
    return line;
  };
  chart.series.push_back(series("float64 reference", report.reference_warp_pops_per_step, 0, 1));
  for (size_t i = 0; i < report.modes.size(); ++i)
    chart.series.push_back(series(report.modes[i].name, report.modes[i].warp_pops_per_step, i, 0));
  return plot::line_chart_svg(chart);
}

}  // namespace tilesplat::accuracy
