// Scatter plots with their Pareto front (bench_plot.h): error against time per accuracy mode.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bench_plot.h"
#include "svg_parts.h"

namespace tilesplat::plot {

using namespace svg;  // the charts' pieces (svg_parts.h)

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
      dominated =
          j != i && eligible(q) && q.x <= p.x && at_least_as_good(q.y, p.y) && (q.x < p.x || q.y != p.y);
    }
    if (!dominated) front.push_back(i);
  }
  std::stable_sort(front.begin(), front.end(), [&](size_t a, size_t b) { return points[a].x < points[b].x; });
  return front;
}

namespace {

constexpr double kHeight = 560;
constexpr double kRadius = 5;
constexpr double kLabelGap = 4;     // between a circle and its label
constexpr double kLineHeight = 14;  // one step of a label's nudge
constexpr double kAscent = 10;      // of a label above its baseline, and its descent below
constexpr double kDescent = 3;
// The band past the axis's end where a y without a place on the axis goes.
constexpr double kBand = 24;
const char* const kParetoStyle =
    "fill=\"none\" stroke=\"#555\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"";

// A drawn point: its circle, its label (with the note of a clamped y) and where the label went.
struct Placed {
  double cx = 0;
  double cy = 0;
  std::string label;
  bool on_front = false;
  double label_x = 0;
  double baseline = 0;
  bool label_right = true;
};

struct Box {
  double x0, y0, x1, y1;
  bool overlaps(const Box& other) const {
    return x0 < other.x1 && other.x0 < x1 && y0 < other.y1 && other.y0 < y1;
  }
};

// The legend line under the titles, and the plot area below it with its axes (and, for y values without a
// place on the axis, bands past the axis's ends: +inf at the top, whose tick reads infinity, and the rest at
// the bottom, not onto an end tick where they would read as that value).
PlotArea draw_frame(std::string& out, const ScatterChart& chart,
                    const std::vector<ScatterPoint>& drawn_points, const std::vector<double>& xs,
                    const std::vector<double>& ys, double width) {
  const double legend_y = draw_titles(out, chart.title, chart.subtitle) + 8;
  out += "<g class=\"legend\">\n" + line(kMargin, legend_y, kMargin + 26, legend_y, kParetoStyle);
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
  return area;
}

// Each point's circle on the area, a y without a place on the axis on its band with a note in its label.
std::vector<Placed> place_points(const ScatterChart& chart, const std::vector<ScatterPoint>& drawn_points,
                                 const PlotArea& area) {
  std::vector<Placed> placed(drawn_points.size());
  for (size_t d = 0; d < drawn_points.size(); ++d) {
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
  return placed;
}

// Labels, top to bottom: beside the point on the right, else on the left where the right would leave the
// chart, else moved down or up a line at a time until they clear the labels placed so far and every circle.
// A crowded chart may still overlap; it stays readable in the tooltips.
void place_labels(std::vector<Placed>& placed, const PlotArea& area, double width) {
  std::vector<Box> obstacles;
  for (const Placed& p : placed)
    obstacles.push_back({p.cx - kRadius, p.cy - kRadius, p.cx + kRadius, p.cy + kRadius});
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
        const bool inside = box.x0 >= area.left + 2 && box.x1 <= width - kMargin &&
                            box.y0 >= area.top - kLineHeight && box.y1 <= area.bottom - 2;
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
}

// The Pareto front's line, the leaders of moved labels, the circles (with their data and tooltips), the
// labels.
std::string draw_points(const ScatterChart& chart, const std::vector<ScatterPoint>& drawn_points,
                        const std::vector<Placed>& placed, const std::vector<size_t>& front) {
  std::string out = "<g class=\"points\">\n";
  std::string coordinates;
  for (const size_t d : front) {
    if (!coordinates.empty()) coordinates += ' ';
    coordinates += num(placed[d].cx) + "," + num(placed[d].cy);
  }
  out += "<polyline class=\"pareto\" points=\"" + coordinates + "\" " + kParetoStyle + "/>\n";
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
           (p.on_front ? "1" : "0") + "\" cx=\"" + num(p.cx) + "\" cy=\"" + num(p.cy) + "\" r=\"" +
           num(kRadius) + "\" fill=\"" + color(point.color) + "\" " + stroke + "><title>" +
           xml_escape(point.label + ": " + chart.x_label + " " + data_number(point.x) + ", " + chart.y_label +
                      " " + data_number(point.y)) +
           "</title></circle>\n";
  }
  for (size_t d = 0; d < placed.size(); ++d) {
    const Placed& p = placed[d];
    out += text(p.label_x, p.baseline, p.label,
                "class=\"point-label\" data-label=\"" + xml_escape(drawn_points[d].label) +
                    "\" text-anchor=\"" + (p.label_right ? "start" : "end") + "\"");
  }
  out += "</g>\n";
  return out;
}

}  // namespace

std::string scatter_svg(const ScatterChart& chart) {
  // The points with a place on the x axis; y values without one are clamped below.
  std::vector<ScatterPoint> drawn_points;
  std::vector<double> xs;
  std::vector<double> ys;
  for (const ScatterPoint& point : chart.points) {
    if (!usable(point.x, chart.x_scale)) continue;
    drawn_points.push_back(point);
    xs.push_back(point.x);
    if (usable(point.y, chart.y_scale)) ys.push_back(point.y);
  }
  const double width = std::max(kMinWidth, title_width(chart.title, chart.subtitle));
  std::string out;
  const PlotArea area = draw_frame(out, chart, drawn_points, xs, ys, width);
  std::vector<Placed> placed = place_points(chart, drawn_points, area);
  const std::vector<size_t> front = pareto_front(drawn_points, chart.y_higher_is_better);
  for (const size_t d : front) placed[d].on_front = true;
  place_labels(placed, area, width);
  out += draw_points(chart, drawn_points, placed, front);
  return document_open(width, kHeight) + out + "</svg>\n";
}

}  // namespace tilesplat::plot
