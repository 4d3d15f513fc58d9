#include "bench_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace tilesplat::plot {

namespace {

// Tableau 10: distinguishable, and still readable printed in grey.
constexpr const char* kPalette[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                                    "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"};
constexpr size_t kPaletteSize = sizeof kPalette / sizeof kPalette[0];
constexpr const char* kDashes[] = {"", "7 4", "2 3", "9 3 2 3"};
constexpr size_t kDashCount = sizeof kDashes / sizeof kDashes[0];

constexpr double kMargin = 16;
constexpr double kFontSize = 12;
constexpr double kTitleSize = 16;
constexpr double kMinWidth = 960;

const char* color(size_t index) { return kPalette[index % kPaletteSize]; }

// Coordinates with three decimals: exact enough for any screen, and short.
std::string num(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3f", value);
  return buffer;
}

// No font metrics without a font library: 0.6 em per character is the average advance of a
// sans-serif face, enough to reserve room for labels. UTF-8 continuation bytes are not characters.
double text_width(std::string_view text, double font_size) {
  const auto characters = std::count_if(text.begin(), text.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  });
  return 0.6 * font_size * static_cast<double>(characters);
}

// A tick label: as many decimals as the step needs, no more.
std::string tick_label(double value, double step) {
  int decimals = 0;
  if (step > 0 && step < 1) decimals = static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string text(double x, double y, std::string_view content, std::string_view attributes = {}) {
  std::string out = "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\"";
  if (!attributes.empty()) {
    out += ' ';
    out += attributes;
  }
  return out + ">" + xml_escape(content) + "</text>\n";
}

std::string line(double x1, double y1, double x2, double y2, std::string_view attributes) {
  return "<line x1=\"" + num(x1) + "\" y1=\"" + num(y1) + "\" x2=\"" + num(x2) + "\" y2=\"" + num(y2) + "\" " +
         std::string(attributes) + "/>\n";
}

std::string document_open(double width, double height) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(width) + "\" height=\"" + num(height) +
         "\" viewBox=\"0 0 " + num(width) + " " + num(height) + "\" font-family=\"sans-serif\" font-size=\"" +
         num(kFontSize) + "\">\n<rect class=\"background\" width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
}

// Title and subtitle at the top; returns the y below them.
double draw_titles(std::string& out, const std::string& title, const std::string& subtitle) {
  double y = kMargin + kTitleSize;
  out += text(kMargin, y, title, "class=\"title\" font-size=\"" + num(kTitleSize) + "\" font-weight=\"bold\"");
  if (!subtitle.empty()) {
    y += 18;
    out += text(kMargin, y, subtitle, "class=\"subtitle\" fill=\"#555\"");
  }
  return y + 10;
}

double title_width(const std::string& title, const std::string& subtitle) {
  return std::max(text_width(title, kTitleSize), text_width(subtitle, kFontSize)) + 2 * kMargin;
}

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
      case Scale::kLog2: return std::log2(value);
      case Scale::kLog10: return std::log10(value);
      case Scale::kLinear: break;
    }
    return value;
  }
  // 0 at lo, 1 at hi.
  double fraction(double value) const { return hi > lo ? (transform(value) - lo) / (hi - lo) : 0; }
};

bool usable(double value, Scale scale) { return std::isfinite(value) && (scale == Scale::kLinear || value > 0); }

Axis make_axis(Scale scale, const std::vector<double>& values) {
  Axis axis;
  axis.scale = scale;
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  for (const double value : values) {
    if (!usable(value, scale)) continue;
    min = std::min(min, value);
    max = std::max(max, value);
  }
  if (scale == Scale::kLinear) {
    // From 0, so that lengths compare as ratios.
    axis.ticks = linear_ticks(std::isfinite(max) ? max : 0);
    const double step = axis.ticks.size() > 1 ? axis.ticks[1] : 1;
    for (const double tick : axis.ticks) axis.labels.push_back(tick_label(tick, step));
    axis.lo = 0;
    axis.hi = axis.ticks.back();
    return axis;
  }
  if (!std::isfinite(min)) min = max = 1;
  const double base = scale == Scale::kLog2 ? 2 : 10;
  const int first = static_cast<int>(std::floor(axis.transform(min) + 1e-9));
  int last = static_cast<int>(std::ceil(axis.transform(max) - 1e-9));
  if (last == first) ++last;
  // Powers of two every 1, 2, ... exponents so that labels do not collide; decades every one.
  const int stride = scale == Scale::kLog2 ? std::max(1, (last - first + 13) / 14) : 1;
  for (int exponent = first; exponent <= last; exponent += stride) {
    const double value = std::pow(base, exponent);
    axis.ticks.push_back(value);
    axis.labels.push_back(scale == Scale::kLog2 ? std::to_string(exponent) : tick_label(value, value));
  }
  // Within one or two decades, 2 and 5 times each decade too, or there would be two labels.
  if (scale == Scale::kLog10 && last - first <= 2) {
    std::vector<std::pair<double, std::string>> ticks;
    for (int exponent = first; exponent <= last; ++exponent)
      for (const double mantissa : {1.0, 2.0, 5.0}) {
        const double value = mantissa * std::pow(10.0, exponent);
        if (std::log10(value) <= last + 1e-9) ticks.emplace_back(value, tick_label(value, std::pow(10.0, exponent)));
      }
    axis.ticks.clear();
    axis.labels.clear();
    for (auto& [value, label] : ticks) {
      axis.ticks.push_back(value);
      axis.labels.push_back(std::move(label));
    }
  }
  axis.power_of_two_labels = scale == Scale::kLog2;
  axis.lo = first;
  axis.hi = last;
  return axis;
}

std::string tick_text(const Axis& axis, size_t i, double x, double y, std::string_view anchor) {
  const std::string attributes = "class=\"tick-label\" text-anchor=\"" + std::string(anchor) + "\"";
  if (!axis.power_of_two_labels) return text(x, y, axis.labels[i], attributes);
  return "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\" " + attributes + ">2<tspan dy=\"-5\" font-size=\"9\">" +
         xml_escape(axis.labels[i]) + "</tspan></text>\n";
}

// A linear axis over the values' range only, from the round tick at or below the smallest to the one
// at or above the largest: for a scatter plot, where positions compare and lengths do not (PSNR from
// 0 dB would squeeze every accuracy mode into the top of the chart).
Axis make_range_axis(const std::vector<double>& values) {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  for (const double value : values) {
    if (!std::isfinite(value)) continue;
    min = std::min(min, value);
    max = std::max(max, value);
  }
  if (!std::isfinite(min)) return make_axis(Scale::kLinear, {});
  // A span lost in the values' rounding (or none: one value) gets a tenth of their size, so that the
  // tick count stays small and the tick indices below stay exact integers.
  const double magnitude = std::max(std::fabs(min), std::fabs(max));
  double span = max - min;
  if (!(span > magnitude * 1e-9)) span = magnitude > 0 ? magnitude * 0.1 : 1;
  const std::vector<double> steps = linear_ticks(span, 6);
  const double step = steps.size() > 1 && steps[1] > 0 ? steps[1] : span;
  const double first = std::floor(min / step + 1e-9);
  double last = std::ceil(max / step - 1e-9);
  if (last <= first) last = first + 1;
  Axis axis;
  const int count = static_cast<int>(last - first);
  for (int i = 0; i <= count; ++i) {
    double value = (first + i) * step;
    if (value == 0) value = 0;  // never "-0"
    axis.ticks.push_back(value);
    axis.labels.push_back(tick_label(value, step));
  }
  axis.lo = axis.ticks.front();
  axis.hi = axis.ticks.back();
  return axis;
}

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
std::string draw_axes(const PlotArea& area, const std::string& x_label, const std::string& y_label) {
  std::string out = "<g class=\"axis\">\n";
  for (size_t i = 0; i < area.x_axis.ticks.size(); ++i) {
    const double x = area.px(area.x_axis.ticks[i]);
    out += line(x, area.top, x, area.bottom, "stroke=\"#e3e3e3\"");
    out += line(x, area.bottom, x, area.bottom + 5, "stroke=\"#333\"");
    out += tick_text(area.x_axis, i, x, area.bottom + 19, "middle");
  }
  for (size_t i = 0; i < area.y_axis.ticks.size(); ++i) {
    const double y = area.py(area.y_axis.ticks[i]);
    out += line(area.left, y, area.right, y, "stroke=\"#e3e3e3\"");
    out += line(area.left - 5, y, area.left, y, "stroke=\"#333\"");
    out += tick_text(area.y_axis, i, area.left - 8, y + 4, "end");
  }
  out += line(area.left, area.bottom, area.right, area.bottom, "stroke=\"#333\"");
  out += line(area.left, area.top, area.left, area.bottom, "stroke=\"#333\"");
  out += text((area.left + area.right) / 2, area.bottom + 36, x_label, "class=\"axis-label\" text-anchor=\"middle\"");
  const double y_label_x = kMargin + 10;
  const double y_label_y = (area.top + area.bottom) / 2;
  out += text(y_label_x, y_label_y, y_label,
              "class=\"axis-label\" text-anchor=\"middle\" transform=\"rotate(-90 " + num(y_label_x) + " " +
                  num(y_label_y) + ")\"");
  return out + "</g>\n";
}

// A value for a data- attribute: enough digits to read it back, and words for what is not a number.
std::string data_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

}  // namespace

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        // XML 1.0 allows no control characters but tab, newline and carriage return.
        if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r')
          out += ' ';
        else
          out += c;
    }
  }
  return out;
}

std::vector<double> linear_ticks(double max, int max_ticks) {
  if (!(max > 0) || !std::isfinite(max)) return {0, 1};
  const double rough = max / std::max(1, max_ticks);
  const double power = std::pow(10.0, std::floor(std::log10(rough)));
  double step = 10 * power;
  for (const double mantissa : {1.0, 2.0, 5.0}) {
    if (mantissa * power >= rough * (1 - 1e-9)) {
      step = mantissa * power;
      break;
    }
  }
  if (!(step > 0)) return {0, max};  // max so small that max / max_ticks underflows
  std::vector<double> ticks;
  for (int i = 0;; ++i) {
    ticks.push_back(i * step);
    if (i * step >= max * (1 - 1e-9)) break;
  }
  return ticks;
}

// ---------------------------------------------------------------------------------------------
// Stacked horizontal bars

std::string stacked_bar_svg(const StackedBarChart& chart) {
  constexpr double kBarHeight = 18;
  constexpr double kBarPitch = 26;
  constexpr double kHeadingHeight = 24;
  constexpr double kSwatch = 12;
  constexpr double kMinPlotWidth = 300;

  double label_width = 0;
  double note_width = 0;
  std::vector<double> totals;
  for (const auto& bar : chart.bars) {
    label_width = std::max(label_width, text_width(bar.label, kFontSize));
    note_width = std::max(note_width, text_width(bar.note, kFontSize));
    double total = 0;
    for (const double value : bar.values)
      if (std::isfinite(value) && value > 0) total += value;
    totals.push_back(total);
  }
  const double left = kMargin + label_width + 10;
  const double right_reserve = kMargin + (note_width > 0 ? note_width + 8 : 0);
  const double width =
      std::max({kMinWidth, title_width(chart.title, chart.subtitle), left + kMinPlotWidth + right_reserve});
  const double plot_right = width - right_reserve;

  // Titles, then the legend in rows as wide as the chart.
  std::string head;
  double y = draw_titles(head, chart.title, chart.subtitle);
  head += "<g class=\"legend\">\n";
  double legend_x = kMargin;
  for (size_t s = 0; s < chart.segments.size(); ++s) {
    const double entry_width = kSwatch + 4 + text_width(chart.segments[s], kFontSize) + 16;
    if (legend_x > kMargin && legend_x + entry_width > width - kMargin) {
      legend_x = kMargin;
      y += 20;
    }
    head += "<rect class=\"swatch\" x=\"" + num(legend_x) + "\" y=\"" + num(y) + "\" width=\"" + num(kSwatch) +
            "\" height=\"" + num(kSwatch) + "\" fill=\"" + color(s) + "\"/>\n";
    head += text(legend_x + kSwatch + 4, y + 10.5, chart.segments[s], "class=\"legend-label\"");
    legend_x += entry_width;
  }
  head += "</g>\n";
  y += (chart.segments.empty() ? 0 : 20) + 8;
  const double plot_top = y;

  const Axis axis = make_axis(Scale::kLinear, totals);
  const double scale = (plot_right - left) / (axis.hi > 0 ? axis.hi : 1);

  // The bars before the axis: the gridlines go under them but reach the axis below the last one.
  std::string body = "<g class=\"bars\">\n";
  const std::string* previous_group = nullptr;
  for (size_t b = 0; b < chart.bars.size(); ++b) {
    const auto& bar = chart.bars[b];
    if (!bar.group.empty() && (!previous_group || *previous_group != bar.group)) {
      body += text(kMargin, y + 16, bar.group, "class=\"group\" font-weight=\"bold\"");
      y += kHeadingHeight;
    }
    previous_group = &bar.group;
    const double top = y + (kBarPitch - kBarHeight) / 2;
    body += text(left - 6, top + kBarHeight / 2 + 4, bar.label, "class=\"bar-label\" text-anchor=\"end\"");
    double x = left;
    for (size_t s = 0; s < bar.values.size() && s < chart.segments.size(); ++s) {
      const double value = bar.values[s];
      if (!std::isfinite(value) || value <= 0) continue;
      const double length = value * scale;
      char value_text[48];
      std::snprintf(value_text, sizeof value_text, "%.3f", value);
      body += "<rect class=\"segment\" data-bar=\"" + std::to_string(b) + "\" data-segment=\"" +
              xml_escape(chart.segments[s]) + "\" data-value=\"" + value_text + "\" x=\"" + num(x) + "\" y=\"" +
              num(top) + "\" width=\"" + num(length) + "\" height=\"" + num(kBarHeight) + "\" fill=\"" + color(s) +
              "\"><title>" + xml_escape(bar.label + ", " + chart.segments[s] + ": " + value_text) +
              "</title></rect>\n";
      x += length;
    }
    if (!bar.note.empty()) body += text(x + 6, top + kBarHeight / 2 + 4, bar.note, "class=\"note\" fill=\"#333\"");
    y += kBarPitch;
  }
  body += "</g>\n";

  const double axis_y = y + 4;
  std::string grid = "<g class=\"axis\">\n";
  for (size_t i = 0; i < axis.ticks.size(); ++i) {
    const double x = left + axis.ticks[i] * scale;
    grid += line(x, plot_top, x, axis_y, "stroke=\"#e3e3e3\"");
    grid += line(x, axis_y, x, axis_y + 5, "stroke=\"#333\"");
    grid += tick_text(axis, i, x, axis_y + 18, "middle");
  }
  grid += line(left, axis_y, plot_right, axis_y, "stroke=\"#333\"");
  grid += text((left + plot_right) / 2, axis_y + 36, chart.axis_label, "class=\"axis-label\" text-anchor=\"middle\"");
  grid += "</g>\n";

  const double height = axis_y + 36 + kMargin;
  return document_open(width, height) + head + grid + body + "</svg>\n";
}

// ---------------------------------------------------------------------------------------------
// Lines

std::string line_chart_svg(const LineChart& chart) {
  constexpr double kHeight = 560;
  constexpr double kLegendLine = 26;

  std::vector<double> xs;
  std::vector<double> ys;
  double legend_width = 0;
  for (const auto& series : chart.series) {
    legend_width = std::max(legend_width, kLegendLine + 6 + text_width(series.label, kFontSize));
    for (const auto& [x, y] : series.points) {
      xs.push_back(x);
      ys.push_back(y);
    }
  }
  const double width = std::max(kMinWidth, title_width(chart.title, chart.subtitle));
  std::string out;
  const double top = draw_titles(out, chart.title, chart.subtitle) + 8;
  PlotArea area;
  area.left = kMargin + 22 + 52;  // the rotated y label, then the tick labels
  area.right = width - kMargin - (legend_width > 0 ? legend_width + 16 : 0);
  area.top = top;
  area.bottom = kHeight - kMargin - 40;
  area.x_axis = make_axis(chart.x_scale, xs);
  area.y_axis = make_axis(chart.y_scale, ys);
  auto px = [&](double x) { return area.px(x); };
  auto py = [&](double y) { return area.py(y); };
  const double right = area.right;
  out += draw_axes(area, chart.x_label, chart.y_label);

  out += "<g class=\"lines\">\n";
  for (const auto& series : chart.series) {
    auto points = series.points;
    std::stable_sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::string coordinates;
    std::string markers;
    for (const auto& [x, y] : points) {
      if (!usable(x, chart.x_scale) || !usable(y, chart.y_scale)) continue;
      if (!coordinates.empty()) coordinates += ' ';
      coordinates += num(px(x)) + "," + num(py(y));
      char value_text[96];
      std::snprintf(value_text, sizeof value_text, "%g, %.4g", x, y);
      markers += "<circle cx=\"" + num(px(x)) + "\" cy=\"" + num(py(y)) + "\" r=\"3\" fill=\"" + color(series.color) +
                 "\"><title>" + xml_escape(series.label + ": " + value_text) + "</title></circle>\n";
    }
    const std::string dash = kDashes[series.dash % kDashCount];
    out += "<polyline class=\"series\" data-series=\"" + xml_escape(series.label) + "\" points=\"" + coordinates +
           "\" fill=\"none\" stroke=\"" + color(series.color) + "\" stroke-width=\"2\"" +
           (dash.empty() ? "" : " stroke-dasharray=\"" + dash + "\"") + "/>\n" + markers;
  }
  out += "</g>\n";

  out += "<g class=\"legend\">\n";
  double legend_y = top + 6;
  const double legend_x = right + 16;
  for (const auto& series : chart.series) {
    const std::string dash = kDashes[series.dash % kDashCount];
    out += line(legend_x, legend_y, legend_x + kLegendLine, legend_y,
                "stroke=\"" + std::string(color(series.color)) + "\" stroke-width=\"2\"" +
                    (dash.empty() ? "" : " stroke-dasharray=\"" + dash + "\""));
    out += text(legend_x + kLegendLine + 6, legend_y + 4, series.label, "class=\"legend-label\"");
    legend_y += 18;
  }
  out += "</g>\n";
  // Drawn last, the legend may run past the plot's bottom with many series: grow to fit it.
  const double height = std::max(kHeight, legend_y + kMargin);
  return document_open(width, height) + out + "</svg>\n";
}

// ---------------------------------------------------------------------------------------------
// Scatter with a Pareto front

std::vector<size_t> pareto_front(const std::vector<ScatterPoint>& points, bool y_higher_is_better) {
  auto eligible = [](const ScatterPoint& point) { return std::isfinite(point.x) && !std::isnan(point.y); };
  auto at_least_as_good = [&](double y, double than) { return y_higher_is_better ? y >= than : y <= than; };
  std::vector<size_t> front;
  for (size_t i = 0; i < points.size(); ++i) {
    const ScatterPoint& p = points[i];
    if (!eligible(p)) continue;
    bool dominated = false;
    for (size_t j = 0; j < points.size() && !dominated; ++j) {
      const ScatterPoint& q = points[j];
      dominated = j != i && eligible(q) && q.x <= p.x && at_least_as_good(q.y, p.y) && (q.x < p.x || q.y != p.y);
    }
    if (!dominated) front.push_back(i);
  }
  std::stable_sort(front.begin(), front.end(), [&](size_t a, size_t b) { return points[a].x < points[b].x; });
  return front;
}

std::string scatter_svg(const ScatterChart& chart) {
  constexpr double kHeight = 560;
  constexpr double kRadius = 5;
  constexpr double kLabelGap = 4;      // between a circle and its label
  constexpr double kLineHeight = 14;   // one step of a label's nudge
  constexpr double kAscent = 10;       // of a label above its baseline, and its descent below
  constexpr double kDescent = 3;
  const std::string pareto_style = "fill=\"none\" stroke=\"#555\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"";

  // The points with a place on the x axis; y values without one are clamped below.
  std::vector<size_t> drawn;
  std::vector<ScatterPoint> drawn_points;
  std::vector<double> xs;
  std::vector<double> ys;
  for (size_t i = 0; i < chart.points.size(); ++i) {
    const ScatterPoint& point = chart.points[i];
    if (!usable(point.x, chart.x_scale)) continue;
    drawn.push_back(i);
    drawn_points.push_back(point);
    xs.push_back(point.x);
    if (usable(point.y, chart.y_scale)) ys.push_back(point.y);
  }

  const double width = std::max(kMinWidth, title_width(chart.title, chart.subtitle));
  std::string out;
  const double legend_y = draw_titles(out, chart.title, chart.subtitle) + 8;
  out += "<g class=\"legend\">\n" + line(kMargin, legend_y, kMargin + 26, legend_y, pareto_style);
  out += text(kMargin + 32, legend_y + 4,
              std::string("Pareto front: no other point is both left of and ") +
                  (chart.y_higher_is_better ? "above" : "below") + " it (outlined)",
              "class=\"legend-label\"");
  out += "</g>\n";

  PlotArea area;
  area.left = kMargin + 22 + 52;  // the rotated y label, then the tick labels
  area.right = width - kMargin - 8;
  area.top = legend_y + 26;
  area.bottom = kHeight - kMargin - 40;
  area.x_axis = make_axis(chart.x_scale, xs);
  area.y_axis = chart.y_scale == Scale::kLinear ? make_range_axis(ys) : make_axis(chart.y_scale, ys);
  // A y without a place on the axis goes on a band past the axis's end, not onto its end tick where
  // it would read as that value: +inf at the top, whose tick reads infinity, and the rest at the bottom.
  constexpr double kBand = 24;
  bool infinite_y = false;
  bool other_unusable_y = false;
  for (const ScatterPoint& point : drawn_points) {
    if (usable(point.y, chart.y_scale)) continue;
    if (point.y == std::numeric_limits<double>::infinity())
      infinite_y = true;
    else
      other_unusable_y = true;
  }
  area.y_band_top = infinite_y ? kBand : 0;
  area.y_band_bottom = other_unusable_y ? kBand : 0;
  out += draw_axes(area, chart.x_label, chart.y_label);
  if (infinite_y) {
    out += line(area.left, area.top, area.right, area.top, "stroke=\"#e3e3e3\" stroke-dasharray=\"2 3\"");
    out += text(area.left - 8, area.top + 4, "\u221E", "class=\"tick-label\" text-anchor=\"end\"");
  }

  struct Placed {
    double cx = 0;
    double cy = 0;
    std::string label;  // with the note of a clamped y
    bool on_front = false;
    double label_x = 0;
    double baseline = 0;
    bool label_right = true;
  };
  std::vector<Placed> placed(drawn.size());
  for (size_t d = 0; d < drawn.size(); ++d) {
    const ScatterPoint& point = drawn_points[d];
    Placed& p = placed[d];
    p.cx = area.px(point.x);
    p.label = point.label;
    if (usable(point.y, chart.y_scale)) {
      p.cy = area.py(point.y);
    } else if (point.y == std::numeric_limits<double>::infinity()) {
      p.cy = area.top;
      p.label += chart.y_higher_is_better ? " (identical)" : " (y = inf)";
    } else {
      p.cy = area.bottom;
      p.label += " (y = " + data_number(point.y) + ")";
    }
  }
  const std::vector<size_t> front = pareto_front(drawn_points, chart.y_higher_is_better);
  for (const size_t d : front) placed[d].on_front = true;

  // Labels, top to bottom: beside the point on the right, else on the left where the right would
  // leave the chart, else moved down or up a line at a time until they clear the labels placed so
  // far and every circle. A crowded chart may still overlap; it stays readable in the tooltips.
  struct Box {
    double x0, y0, x1, y1;
    bool overlaps(const Box& other) const {
      return x0 < other.x1 && other.x0 < x1 && y0 < other.y1 && other.y0 < y1;
    }
  };
  std::vector<Box> obstacles;
  for (const Placed& p : placed) obstacles.push_back({p.cx - kRadius, p.cy - kRadius, p.cx + kRadius, p.cy + kRadius});
  std::vector<size_t> order(placed.size());
  for (size_t d = 0; d < order.size(); ++d) order[d] = d;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return placed[a].cy != placed[b].cy ? placed[a].cy < placed[b].cy : placed[a].cx < placed[b].cx;
  });
  for (const size_t d : order) {
    Placed& p = placed[d];
    const double label_width = text_width(p.label, kFontSize);
    bool found = false;
    bool have_fallback = false;
    double fallback_x = p.cx + kRadius + kLabelGap;
    double fallback_baseline = p.cy + 4;
    bool fallback_right = true;
    for (int step = 0; step <= 8 && !found; ++step) {
      const double offset = (step % 2 == 1 ? 1 : -1) * ((step + 1) / 2) * kLineHeight;  // 0, +1, -1, +2, ...
      for (const bool right_side : {true, false}) {
        const double x0 = right_side ? p.cx + kRadius + kLabelGap : p.cx - kRadius - kLabelGap - label_width;
        const double baseline = p.cy + 4 + offset;
        const Box box{x0, baseline - kAscent, x0 + label_width, baseline + kDescent};
        const bool inside = box.x0 >= area.left + 2 && box.x1 <= width - kMargin && box.y0 >= area.top - kLineHeight &&
                            box.y1 <= area.bottom - 2;
        if (!inside) continue;
        if (!have_fallback) {
          have_fallback = true;
          fallback_x = x0;
          fallback_baseline = baseline;
          fallback_right = right_side;
        }
        bool clear = true;
        for (size_t o = 0; o < obstacles.size() && clear; ++o)
          if (o != d) clear = !box.overlaps(obstacles[o]);
        if (!clear) continue;
        p.label_x = right_side ? x0 : x0 + label_width;
        p.baseline = baseline;
        p.label_right = right_side;
        obstacles.push_back(box);
        found = true;
        break;
      }
    }
    if (!found) {
      p.label_x = fallback_right ? fallback_x : fallback_x + label_width;
      p.baseline = fallback_baseline;
      p.label_right = fallback_right;
    }
  }

  out += "<g class=\"points\">\n";
  std::string coordinates;
  for (const size_t d : front) {
    if (!coordinates.empty()) coordinates += ' ';
    coordinates += num(placed[d].cx) + "," + num(placed[d].cy);
  }
  out += "<polyline class=\"pareto\" points=\"" + coordinates + "\" " + pareto_style + "/>\n";
  // A label moved off its point's line gets a leader back to it.
  for (const Placed& p : placed)
    if (std::fabs(p.baseline - (p.cy + 4)) > 0.5)
      out += line(p.cx, p.cy, p.label_x + (p.label_right ? -1 : 1), p.baseline - 4,
                  "class=\"leader\" stroke=\"#999\" stroke-width=\"0.75\"");
  for (size_t d = 0; d < placed.size(); ++d) {
    const ScatterPoint& point = drawn_points[d];
    const Placed& p = placed[d];
    const std::string stroke =
        p.on_front ? "stroke=\"#222\" stroke-width=\"1.5\"" : "stroke=\"white\" stroke-width=\"1\"";
    out += "<circle class=\"point\" data-label=\"" + xml_escape(point.label) + "\" data-x=\"" +
           data_number(point.x) + "\" data-y=\"" + data_number(point.y) + "\" data-pareto=\"" +
           (p.on_front ? "1" : "0") + "\" cx=\"" + num(p.cx) + "\" cy=\"" + num(p.cy) + "\" r=\"" + num(kRadius) +
           "\" fill=\"" + color(point.color) + "\" " + stroke + "><title>" +
           xml_escape(point.label + ": " + chart.x_label + " " + data_number(point.x) + ", " + chart.y_label + " " +
                      data_number(point.y)) +
           "</title></circle>\n";
  }
  for (size_t d = 0; d < placed.size(); ++d) {
    const Placed& p = placed[d];
    out += text(p.label_x, p.baseline, p.label,
                "class=\"point-label\" data-label=\"" + xml_escape(drawn_points[d].label) + "\" text-anchor=\"" +
                    (p.label_right ? "start" : "end") + "\"");
  }
  out += "</g>\n";
  return document_open(width, kHeight) + out + "</svg>\n";
}

}  // namespace tilesplat::plot
