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
  const double left = kMargin + 22 + 52;  // the rotated y label, then the tick labels
  const double right = width - kMargin - (legend_width > 0 ? legend_width + 16 : 0);
  const double bottom = kHeight - kMargin - 40;
  const Axis x_axis = make_axis(chart.x_scale, xs);
  const Axis y_axis = make_axis(chart.y_scale, ys);
  auto px = [&](double x) { return left + x_axis.fraction(x) * (right - left); };
  auto py = [&](double y) { return bottom - y_axis.fraction(y) * (bottom - top); };

  out += "<g class=\"axis\">\n";
  for (size_t i = 0; i < x_axis.ticks.size(); ++i) {
    const double x = px(x_axis.ticks[i]);
    out += line(x, top, x, bottom, "stroke=\"#e3e3e3\"");
    out += line(x, bottom, x, bottom + 5, "stroke=\"#333\"");
    out += tick_text(x_axis, i, x, bottom + 19, "middle");
  }
  for (size_t i = 0; i < y_axis.ticks.size(); ++i) {
    const double y = py(y_axis.ticks[i]);
    out += line(left, y, right, y, "stroke=\"#e3e3e3\"");
    out += line(left - 5, y, left, y, "stroke=\"#333\"");
    out += tick_text(y_axis, i, left - 8, y + 4, "end");
  }
  out += line(left, bottom, right, bottom, "stroke=\"#333\"");
  out += line(left, top, left, bottom, "stroke=\"#333\"");
  out += text((left + right) / 2, bottom + 36, chart.x_label, "class=\"axis-label\" text-anchor=\"middle\"");
  const double y_label_x = kMargin + 10;
  const double y_label_y = (top + bottom) / 2;
  out += text(y_label_x, y_label_y, chart.y_label,
              "class=\"axis-label\" text-anchor=\"middle\" transform=\"rotate(-90 " + num(y_label_x) + " " +
                  num(y_label_y) + ")\"");
  out += "</g>\n";

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

}  // namespace tilesplat::plot
