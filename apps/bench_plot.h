// SVG charts for tilesplat-bench, written by hand so that the apps need no plotting dependency:
// stacked horizontal bars (per-pass GPU time per sort strategy) and lines (sort throughput against
// key count). Both return the whole document; the caller writes it (atomically).
//
// The elements carry classes so that tests and scripts can read the numbers back: every bar
// segment is <rect class="segment" data-bar="I" data-segment="NAME" ...>, every legend entry a
// <text class="legend-label">, every line a <polyline class="series" data-series="LABEL">.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tilesplat::plot {

struct StackedBar {
  std::string group;           // bars of one group are drawn together under it as a heading ("" = none)
  std::string label;           // left of the bar
  std::vector<double> values;  // one per StackedBarChart::segments; a value <= 0 or not finite draws nothing
  std::string note;            // right of the bar's end, e.g. "gpu frame 51.8 ms" (may be empty)
};

struct StackedBarChart {
  std::string title;
  std::string subtitle;
  std::string axis_label;             // under the value axis, e.g. "median GPU time (ms)"
  std::vector<std::string> segments;  // names, in stacking (and legend) order
  std::vector<StackedBar> bars;       // top to bottom
};

// Segment lengths are proportional to the values; the axis starts at 0 and ends at the first tick at
// or past the longest bar.
std::string stacked_bar_svg(const StackedBarChart& chart);

enum class Scale { kLinear, kLog2, kLog10 };

struct LineSeries {
  std::string label;
  size_t color = 0;  // index into the palette (wraps): series that belong together share a colour
  size_t dash = 0;   // 0 solid, then dashed, dotted, ... (wraps)
  std::vector<std::pair<double, double>> points;  // (x, y); on a log axis, points <= 0 are left out
};

struct LineChart {
  std::string title;
  std::string subtitle;
  std::string x_label;
  std::string y_label;
  Scale x_scale = Scale::kLinear;
  Scale y_scale = Scale::kLinear;
  std::vector<LineSeries> series;
};

std::string line_chart_svg(const LineChart& chart);

// Tick values for a linear axis over [0, max]: 0, step, 2 step, ... with step 1, 2 or 5 times a power
// of ten, at most about max_ticks + 1 of them, the last one >= max.
std::vector<double> linear_ticks(double max, int max_ticks = 8);

// Text for SVG character data and attribute values.
std::string xml_escape(std::string_view text);

}  // namespace tilesplat::plot
