// The SVG pieces the bench's charts are drawn with (bench_plot.cpp, bench_plot_scatter.cpp): text and
// lines, the document and its titles, axes (linear from 0, over a range, or logarithmic) and the plot area
// between them. Internal to the charts; bench_plot.h is their interface.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "bench_plot.h"

namespace tilesplat::plot::svg {

// Tableau 10: distinguishable, and still readable printed in grey.
inline constexpr const char* kPalette[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                                           "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"};
inline constexpr size_t kPaletteSize = sizeof kPalette / sizeof kPalette[0];
inline constexpr const char* kDashes[] = {"", "7 4", "2 3", "9 3 2 3"};
inline constexpr size_t kDashCount = sizeof kDashes / sizeof kDashes[0];

inline constexpr double kMargin = 16;
inline constexpr double kFontSize = 12;
inline constexpr double kTitleSize = 16;
inline constexpr double kMinWidth = 960;

inline const char* color(size_t index) {
  return kPalette[index % kPaletteSize];
}

// Coordinates with three decimals: exact enough for any screen, and short.
std::string num(double value);
// No font metrics without a font library: 0.6 em per character is the average advance of a
// sans-serif face, enough to reserve room for labels. UTF-8 continuation bytes are not characters.
double text_width(std::string_view text, double font_size);
// A tick label: as many decimals as the step needs, no more.
std::string tick_label(double value, double step);
std::string text(double x, double y, std::string_view content, std::string_view attributes = {});
std::string line(double x1, double y1, double x2, double y2, std::string_view attributes);
std::string document_open(double width, double height);
// Title and subtitle at the top; returns the y below them.
double draw_titles(std::string& out, const std::string& title, const std::string& subtitle);
double title_width(const std::string& title, const std::string& subtitle);

// An axis in its own coordinates (a log axis in exponents): the domain and where the ticks go.
struct Axis {
  Scale scale = Scale::kLinear;
  double lo = 0;
  double hi = 1;
  std::vector<double> ticks;        // data values
  std::vector<std::string> labels;  // one per tick; "2^10" is written with a superscript
  bool power_of_two_labels = false;

  double transform(double value) const {
    switch (scale) {
      case Scale::kLog2:
        return std::log2(value);
      case Scale::kLog10:
        return std::log10(value);
      case Scale::kLinear:
        break;
    }
    return value;
  }
  // 0 at lo, 1 at hi.
  double fraction(double value) const { return hi > lo ? (transform(value) - lo) / (hi - lo) : 0; }
};

// A finite value, and a positive one on a log scale.
bool usable(double value, Scale scale);
// An axis over the values: a linear one from 0 (lengths compare as ratios), else whole powers.
Axis make_axis(Scale scale, const std::vector<double>& values);
std::string tick_text(const Axis& axis, size_t i, double x, double y, std::string_view anchor);
// A linear axis over the values' range only, from the round tick at or below the smallest to the one
// at or above the largest: for a scatter plot, where positions compare and lengths do not (PSNR from
// 0 dB would squeeze every accuracy mode into the top of the chart).
Axis make_range_axis(const std::vector<double>& values);

// The plot area of a chart with two axes, and where data goes in it.
struct PlotArea {
  double left = 0;
  double right = 0;
  double top = 0;
  double bottom = 0;
  // Bands kept free of the y axis's range at its ends, for values that have no place on it.
  double y_band_top = 0;
  double y_band_bottom = 0;
  Axis x_axis;
  Axis y_axis;

  double px(double x) const { return left + x_axis.fraction(x) * (right - left); }
  double py(double y) const {
    const double low = bottom - y_band_bottom;
    return low - y_axis.fraction(y) * (low - top - y_band_top);
  }
};

// Gridlines, ticks and their labels, the axis lines and the axis labels (y rotated, at the left).
std::string draw_axes(const PlotArea& area, const std::string& x_label, const std::string& y_label);
// A value for a data- attribute: enough digits to read it back, and words for what is not a number.
std::string data_number(double value);

}  // namespace tilesplat::plot::svg
