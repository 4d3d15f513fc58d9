// SVG charts for tilesplat-bench, written by hand so that the apps need no plotting dependency:
// stacked horizontal bars (per-pass GPU time per sort strategy), lines (sort throughput against
// key count) and scatter plots with their Pareto front (error against time per accuracy mode). Each
// returns the whole document; the caller writes it (atomically).
//
// The elements carry classes so that tests and scripts can read the numbers back: every bar
// segment is <rect class="segment" data-bar="I" data-segment="NAME" ...>, every legend entry a
// <text class="legend-label">, every line a <polyline class="series" data-series="LABEL">, every
// scatter point a <circle class="point" data-label="LABEL" data-x="X" data-y="Y" data-pareto="0|1">
// with a <text class="point-label"> beside it, and the Pareto front a <polyline class="pareto">.
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

// One point per alternative, e.g. x = median frame time (ms) and y = PSNR (dB) of an accuracy mode.
struct ScatterPoint {
  std::string label;
  double x = 0;  // a cost: lower is better
  double y = 0;
  size_t color = 0;  // index into the palette (wraps)
};

struct ScatterChart {
  std::string title;
  std::string subtitle;
  std::string x_label;
  std::string y_label;
  Scale x_scale = Scale::kLinear;  // a linear x axis starts at 0, so that costs compare as ratios
  Scale y_scale = Scale::kLinear;  // a linear y axis spans the values' range only (round ticks either side)
  bool y_higher_is_better = true;  // PSNR, SSIM: true; an error or a time: false
  std::vector<ScatterPoint> points;
};

// The Pareto front: the indices of the points that no other point dominates, sorted by x (ties in
// index order). q dominates p when q.x <= p.x and q.y is at least as good as p.y, one of them
// strictly. Identical points do not dominate each other: all of them are on the front. A point whose
// x is not finite or whose y is NaN is never on it and dominates nothing; y = +inf or -inf are
// compared as the values they are (PSNR +inf, an identical image, is the best there is).
std::vector<size_t> pareto_front(const std::vector<ScatterPoint>& points, bool y_higher_is_better);

// Points as circles labelled beside them (on the right, or on the left where the label would leave
// the chart, moved up or down by a line or a few to avoid the labels placed before), and the Pareto
// front of the drawn points joined in order of x by a dashed line; its points are drawn outlined.
// A point with a y that has no place on the axis is still drawn, clamped to an end of the y axis
// (on a band past its last tick, so that it does not read as that tick's value), with a note after
// its label: y = +inf at the top, where the axis reads infinity, noted "(identical)" when higher is
// better (the PSNR of an image against itself) and "(y = inf)" otherwise; NaN, -inf, and y <= 0 on a
// log axis at the bottom, noted "(y = VALUE)". data-y keeps the true value ("inf", "-inf", "nan").
// A point whose x has no place (not finite, or <= 0 on a log axis) cannot be drawn and is left out.
std::string scatter_svg(const ScatterChart& chart);

// Tick values for a linear axis over [0, max]: 0, step, 2 step, ... with step 1, 2 or 5 times a power
// of ten, at most about max_ticks + 1 of them, the last one >= max.
std::vector<double> linear_ticks(double max, int max_ticks = 8);

// Text for SVG character data and attribute values.
std::string xml_escape(std::string_view text);

}  // namespace tilesplat::plot
