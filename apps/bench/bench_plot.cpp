#include "bench_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "svg_parts.h"

namespace tilesplat::plot {

using namespace svg;  // the charts' pieces (svg_parts.h)

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
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
    head += "<rect class=\"swatch\" x=\"" + num(legend_x) + "\" y=\"" + num(y) + "\" width=\"" +
            num(kSwatch) + "\" height=\"" + num(kSwatch) + "\" fill=\"" + color(s) + "\"/>\n";
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
              xml_escape(chart.segments[s]) + "\" data-value=\"" + value_text + "\" x=\"" + num(x) +
              "\" y=\"" + num(top) + "\" width=\"" + num(length) + "\" height=\"" + num(kBarHeight) +
              "\" fill=\"" + color(s) + "\"><title>" +
              xml_escape(bar.label + ", " + chart.segments[s] + ": " + value_text) + "</title></rect>\n";
      x += length;
    }
    if (!bar.note.empty())
      body += text(x + 6, top + kBarHeight / 2 + 4, bar.note, "class=\"note\" fill=\"#333\"");
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
  grid += text((left + plot_right) / 2, axis_y + 36, chart.axis_label,
               "class=\"axis-label\" text-anchor=\"middle\"");
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
    std::stable_sort(points.begin(), points.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::string coordinates;
    std::string markers;
    for (const auto& [x, y] : points) {
      if (!usable(x, chart.x_scale) || !usable(y, chart.y_scale)) continue;
      if (!coordinates.empty()) coordinates += ' ';
      coordinates += num(px(x)) + "," + num(py(y));
      char value_text[96];
      std::snprintf(value_text, sizeof value_text, "%g, %.4g", x, y);
      markers += "<circle cx=\"" + num(px(x)) + "\" cy=\"" + num(py(y)) + "\" r=\"3\" fill=\"" +
                 color(series.color) + "\"><title>" + xml_escape(series.label + ": " + value_text) +
                 "</title></circle>\n";
    }
    const std::string dash = kDashes[series.dash % kDashCount];
    out += "<polyline class=\"series\" data-series=\"" + xml_escape(series.label) + "\" points=\"" +
           coordinates + "\" fill=\"none\" stroke=\"" + color(series.color) + "\" stroke-width=\"2\"" +
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
