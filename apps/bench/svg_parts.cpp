#include "svg_parts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace tilesplat::plot::svg {

// Coordinates with three decimals: exact enough for any screen, and short.
std::string num(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3f", value);
  return buffer;
}

// No font metrics without a font library: 0.6 em per character is the average advance of a
// sans-serif face, enough to reserve room for labels. UTF-8 continuation bytes are not characters.
double text_width(std::string_view text, double font_size) {
  const auto characters = std::count_if(
      text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; });
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

std::string text(double x, double y, std::string_view content, std::string_view attributes) {
  std::string out = "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\"";
  if (!attributes.empty()) {
    out += ' ';
    out += attributes;
  }
  return out + ">" + xml_escape(content) + "</text>\n";
}

std::string line(double x1, double y1, double x2, double y2, std::string_view attributes) {
  return "<line x1=\"" + num(x1) + "\" y1=\"" + num(y1) + "\" x2=\"" + num(x2) + "\" y2=\"" + num(y2) +
         "\" " + std::string(attributes) + "/>\n";
}

std::string document_open(double width, double height) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
         num(width) + "\" height=\"" + num(height) + "\" viewBox=\"0 0 " + num(width) + " " + num(height) +
         "\" font-family=\"sans-serif\" font-size=\"" + num(kFontSize) +
         "\">\n<rect class=\"background\" width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
}

// Title and subtitle at the top; returns the y below them.
double draw_titles(std::string& out, const std::string& title, const std::string& subtitle) {
  double y = kMargin + kTitleSize;
  out +=
      text(kMargin, y, title, "class=\"title\" font-size=\"" + num(kTitleSize) + "\" font-weight=\"bold\"");
  if (!subtitle.empty()) {
    y += 18;
    out += text(kMargin, y, subtitle, "class=\"subtitle\" fill=\"#555\"");
  }
  return y + 10;
}

double title_width(const std::string& title, const std::string& subtitle) {
  return std::max(text_width(title, kTitleSize), text_width(subtitle, kFontSize)) + 2 * kMargin;
}

bool usable(double value, Scale scale) {
  return std::isfinite(value) && (scale == Scale::kLinear || value > 0);
}

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
        if (std::log10(value) <= last + 1e-9)
          ticks.emplace_back(value, tick_label(value, std::pow(10.0, exponent)));
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
  return "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\" " + attributes +
         ">2<tspan dy=\"-5\" font-size=\"9\">" + xml_escape(axis.labels[i]) + "</tspan></text>\n";
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
  out += text((area.left + area.right) / 2, area.bottom + 36, x_label,
              "class=\"axis-label\" text-anchor=\"middle\"");
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

}  // namespace tilesplat::plot::svg
