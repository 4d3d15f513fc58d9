// The bench's SVG charts and the --resolutions parser, linked in from the apps' library: the charts
// are checked by reading their numbers back out of the SVG, not by looking at them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "bench_plot.h"
#include "cli.h"

namespace {

using tilesplat::cli::ImageSize;
using tilesplat::cli::parse_resolutions;
using tilesplat::cli::UsageError;
namespace plot = tilesplat::plot;

// The elements named `tag` whose class attribute is `css_class`, each as its attributes and text
// (the writer puts every element of interest on one line, so a regex is enough).
struct Element {
  std::map<std::string, std::string> attributes;
  std::string text;
};

std::vector<Element> elements(const std::string& svg, const std::string& tag, const std::string& css_class) {
  std::vector<Element> found;
  const std::regex element("<" + tag + "\\s([^>]*?)/?>(?:([^<]*)</" + tag + ">)?");
  const std::regex attribute("([\\w-]+)=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), element); it != std::sregex_iterator(); ++it) {
    Element e;
    const std::string attributes = (*it)[1];
    for (auto a = std::sregex_iterator(attributes.begin(), attributes.end(), attribute); a != std::sregex_iterator();
         ++a)
      e.attributes[(*a)[1]] = (*a)[2];
    e.text = (*it)[2];
    if (e.attributes["class"] == css_class) found.push_back(std::move(e));
  }
  return found;
}

double number(const Element& e, const std::string& name) {
  const auto it = e.attributes.find(name);
  EXPECT_NE(it, e.attributes.end()) << "no attribute " << name;
  return it == e.attributes.end() ? NAN : std::strtod(it->second.c_str(), nullptr);
}

size_t occurrences(const std::string& text, const std::string& part) {
  size_t count = 0;
  for (size_t pos = text.find(part); pos != std::string::npos; pos = text.find(part, pos + 1)) ++count;
  return count;
}

// Cheap well-formedness: the prolog, one root, and every element that opens a text closes it.
void expect_svg_document(const std::string& svg) {
  EXPECT_EQ(svg.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_EQ(occurrences(svg, "<svg "), 1u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_EQ(occurrences(svg, "<text "), occurrences(svg, "</text>"));
  EXPECT_EQ(occurrences(svg, "<g "), occurrences(svg, "</g>"));
}

plot::StackedBarChart sample_bars() {
  plot::StackedBarChart chart;
  chart.title = "GPU time per pass: a & b <scene>";
  chart.subtitle = "device";
  chart.axis_label = "GPU time (ms)";
  chart.segments = {"projection", "depth_sort", "tile_sort", "composite"};
  chart.bars = {{"scene 1, 320x180", "radix", {5, 20, 10, 15}, "gpu frame 51.0 ms"},
                {"scene 1, 320x180", "bitonic", {5, 30, 55, 15}, "gpu frame 106.0 ms"},
                {"scene 2, 480x270", "radix", {1.5, 0, 4, 2.5}, ""}};  // no depth_sort: no rect for it
  return chart;
}

TEST(BenchPlot, StackedBarsHaveOneRectPerBarAndPass) {
  const auto chart = sample_bars();
  const std::string svg = plot::stacked_bar_svg(chart);
  expect_svg_document(svg);

  const auto segments = elements(svg, "rect", "segment");
  ASSERT_EQ(segments.size(), 11u) << svg;
  std::map<std::pair<int, std::string>, int> seen;
  for (const auto& e : segments) ++seen[std::make_pair(std::atoi(e.attributes.at("data-bar").c_str()),
                                                       e.attributes.at("data-segment"))];
  for (int bar = 0; bar < 3; ++bar) {
    for (size_t s = 0; s < chart.segments.size(); ++s) {
      const int expected = chart.bars[size_t(bar)].values[s] > 0 ? 1 : 0;
      EXPECT_EQ(seen[std::make_pair(bar, chart.segments[s])], expected) << "bar " << bar << " " << chart.segments[s];
    }
  }
  // The colour tells the pass: the same in every bar.
  std::map<std::string, std::string> fill;
  for (const auto& e : segments) {
    const auto it = fill.emplace(e.attributes.at("data-segment"), e.attributes.at("fill")).first;
    EXPECT_EQ(it->second, e.attributes.at("fill")) << it->first;
  }
  EXPECT_EQ(fill.size(), 4u);
}

TEST(BenchPlot, StackedBarLengthsAreProportionalToTheValues) {
  const auto chart = sample_bars();
  const std::string svg = plot::stacked_bar_svg(chart);
  const auto segments = elements(svg, "rect", "segment");
  ASSERT_FALSE(segments.empty());

  // The scale from the longest segment (tile_sort of bitonic, 55 ms): coordinates are rounded to
  // 0.001 px, which a short segment would magnify.
  double px_per_ms = 0;
  for (const auto& e : segments)
    if (e.attributes.at("data-bar") == "1" && e.attributes.at("data-segment") == "tile_sort")
      px_per_ms = number(e, "width") / 55;
  ASSERT_GT(px_per_ms, 0);
  const double left = number(segments.front(), "x");
  std::map<int, double> end;  // where each bar's last segment ended
  for (const auto& e : segments) {
    const int bar = std::atoi(e.attributes.at("data-bar").c_str());
    size_t s = 0;
    while (chart.segments[s] != e.attributes.at("data-segment")) ++s;
    const double value = chart.bars[size_t(bar)].values[s];
    EXPECT_NEAR(number(e, "width"), value * px_per_ms, 3e-3) << bar << " " << chart.segments[s];
    EXPECT_NEAR(number(e, "data-value"), value, 1e-3);
    // Stacked: each segment starts where the previous one of its bar ended, every bar at the axis origin.
    EXPECT_NEAR(number(e, "x"), end.count(bar) ? end[bar] : left, 3e-3) << bar << " " << chart.segments[s];
    end[bar] = number(e, "x") + number(e, "width");
  }
  EXPECT_NEAR(end[1] - left, 105 * px_per_ms, 1e-2);
  EXPECT_NEAR(end[2] - left, 8 * px_per_ms, 1e-2);

  // The axis agrees with the bars: tick "v" sits v ms from the origin, and the last one is past the longest bar.
  const auto ticks = elements(svg, "text", "tick-label");
  ASSERT_GE(ticks.size(), 3u);
  EXPECT_EQ(ticks.front().text, "0");
  EXPECT_NEAR(number(ticks.front(), "x"), left, 1e-3);
  for (const auto& tick : ticks)
    EXPECT_NEAR(number(tick, "x"), left + std::strtod(tick.text.c_str(), nullptr) * px_per_ms, 3e-3) << tick.text;
  EXPECT_GE(std::strtod(ticks.back().text.c_str(), nullptr), 105);
}

TEST(BenchPlot, StackedBarsHaveLegendGroupsTitleAndNotes) {
  const auto chart = sample_bars();
  const std::string svg = plot::stacked_bar_svg(chart);
  std::vector<std::string> legend;
  for (const auto& e : elements(svg, "text", "legend-label")) legend.push_back(e.text);
  EXPECT_EQ(legend, chart.segments);
  EXPECT_EQ(elements(svg, "rect", "swatch").size(), chart.segments.size());

  std::vector<std::string> groups;
  for (const auto& e : elements(svg, "text", "group")) groups.push_back(e.text);
  EXPECT_EQ(groups, (std::vector<std::string>{"scene 1, 320x180", "scene 2, 480x270"}));
  std::vector<std::string> labels;
  for (const auto& e : elements(svg, "text", "bar-label")) labels.push_back(e.text);
  EXPECT_EQ(labels, (std::vector<std::string>{"radix", "bitonic", "radix"}));
  EXPECT_EQ(elements(svg, "text", "note").size(), 2u);

  const auto title = elements(svg, "text", "title");
  ASSERT_EQ(title.size(), 1u);
  EXPECT_EQ(title.front().text, "GPU time per pass: a &amp; b &lt;scene&gt;");
}

TEST(BenchPlot, EmptyStackedBarChartIsStillADocument) {
  plot::StackedBarChart chart;
  chart.title = "nothing";
  const std::string svg = plot::stacked_bar_svg(chart);
  expect_svg_document(svg);
  EXPECT_TRUE(elements(svg, "rect", "segment").empty());
}

TEST(BenchPlot, LinearTicksAreRoundAndReachTheMaximum) {
  EXPECT_EQ(plot::linear_ticks(121), (std::vector<double>{0, 20, 40, 60, 80, 100, 120, 140}));
  EXPECT_EQ(plot::linear_ticks(100), (std::vector<double>{0, 20, 40, 60, 80, 100}));
  EXPECT_EQ(plot::linear_ticks(0.9, 4), (std::vector<double>{0, 0.5, 1}));
  EXPECT_EQ(plot::linear_ticks(0), (std::vector<double>{0, 1}));
  EXPECT_EQ(plot::linear_ticks(NAN), (std::vector<double>{0, 1}));
}

TEST(BenchPlot, LineChartPlacesPointsOnLogAxes) {
  plot::LineChart chart;
  chart.title = "Sort throughput";
  chart.x_label = "keys";
  chart.y_label = "Mkeys/s";
  chart.x_scale = plot::Scale::kLog2;
  chart.y_scale = plot::Scale::kLog10;
  chart.series = {{"radix, 32-bit keys", 0, 0, {{1024, 1}, {4096, 10}, {16384, 100}}},
                  {"std::sort (cpu), 32-bit keys", 1, 0, {{1024, 50}, {4096, 0}, {16384, 40}}},
                  {"radix, 64-bit keys", 0, 1, {{1024, 0.5}, {16384, 20}}}};
  const std::string svg = plot::line_chart_svg(chart);
  expect_svg_document(svg);

  const auto lines = elements(svg, "polyline", "series");
  ASSERT_EQ(lines.size(), 3u);
  std::vector<std::string> legend;
  for (const auto& e : elements(svg, "text", "legend-label")) legend.push_back(e.text);
  EXPECT_EQ(legend, (std::vector<std::string>{"radix, 32-bit keys", "std::sort (cpu), 32-bit keys",
                                              "radix, 64-bit keys"}));
  EXPECT_EQ(lines[0].attributes.at("stroke"), lines[2].attributes.at("stroke"));  // same sorter, same colour
  EXPECT_NE(lines[0].attributes.at("stroke"), lines[1].attributes.at("stroke"));
  EXPECT_EQ(lines[0].attributes.count("stroke-dasharray"), 0u);  // the key width is the dash
  EXPECT_EQ(lines[2].attributes.count("stroke-dasharray"), 1u);

  // x doubles by 4 and y grows by 10 between the points of the first line: equal steps on log axes.
  std::vector<std::pair<double, double>> points;
  const std::string coordinates = lines[0].attributes.at("points");
  const std::regex pair("(-?[\\d.]+),(-?[\\d.]+)");
  for (auto it = std::sregex_iterator(coordinates.begin(), coordinates.end(), pair); it != std::sregex_iterator(); ++it)
    points.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  ASSERT_EQ(points.size(), 3u);
  EXPECT_NEAR(points[1].first - points[0].first, points[2].first - points[1].first, 2e-3);
  EXPECT_NEAR(points[0].second - points[1].second, points[1].second - points[2].second, 2e-3);
  EXPECT_GT(points[0].second, points[1].second);  // larger values higher up

  // A zero has no place on a log axis: that point is left out, not drawn at -infinity.
  EXPECT_EQ(occurrences(lines[1].attributes.at("points"), ","), 2u);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Scatter with a Pareto front

// The (x, y) pairs of an SVG points attribute.
std::vector<std::pair<double, double>> polyline_points(const std::string& coordinates) {
  std::vector<std::pair<double, double>> points;
  const std::regex pair("(-?[\\d.]+),(-?[\\d.]+)");
  for (auto it = std::sregex_iterator(coordinates.begin(), coordinates.end(), pair); it != std::sregex_iterator(); ++it)
    points.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  return points;
}

// Accuracy modes: (median ms, PSNR dB). The front, by x: fast (5, 30), mid (8, 40), fp32 (10, 50), exact.
plot::ScatterChart sample_scatter() {
  plot::ScatterChart chart;
  chart.title = "PSNR against frame time";
  chart.x_label = "median frame time (ms)";
  chart.y_label = "PSNR (dB)";
  chart.points = {{"exact", 12, 60, 0},  {"fp32", 10, 50, 1},      {"slow & bad", 11, 45, 2},
                  {"mid", 8, 40, 3},     {"fast", 5, 30, 4},       {"dominated by mid", 9, 39.5, 5},
                  {"ties fp32 on y", 10.5, 50, 6}};
  return chart;
}

TEST(BenchPlot, ParetoFrontKeepsTheUndominatedPointsInOrderOfX) {
  const auto chart = sample_scatter();
  EXPECT_EQ(plot::pareto_front(chart.points, true), (std::vector<size_t>{4, 3, 1, 0}));
  // Lower is better (say the y is an error): now only what is both fast and low survives.
  EXPECT_EQ(plot::pareto_front(chart.points, false), (std::vector<size_t>{4}));

  using Points = std::vector<plot::ScatterPoint>;
  // Identical points are both on the front; a y tie at a larger x, or an x tie with a worse y, is not.
  EXPECT_EQ(plot::pareto_front(Points{{"a", 2, 5}, {"b", 1, 3}, {"a again", 2, 5}, {"c", 3, 5}, {"d", 1, 2}}, true),
            (std::vector<size_t>{1, 0, 2}));
  EXPECT_EQ(plot::pareto_front(Points{{"a", 2, 5}, {"b", 1, 3}, {"d", 1, 2}}, false), (std::vector<size_t>{2}));
  // +inf (an identical image's PSNR) is the best y there is; NaN and a non-finite x are never on the front
  // and dominate nothing.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(plot::pareto_front(Points{{"exact", 9, inf}, {"fast", 3, 30}, {"nan", 1, NAN}, {"no time", NAN, 99},
                                      {"infinite time", inf, 99}, {"fp32", 5, 40}, {"slower exact", 10, inf}},
                               true),
            (std::vector<size_t>{1, 5, 0}));
  EXPECT_TRUE(plot::pareto_front({}, true).empty());
  EXPECT_EQ(plot::pareto_front(Points{{"only", 1, 1}}, false), (std::vector<size_t>{0}));
}

TEST(BenchPlot, ScatterDrawsEveryPointWithItsData) {
  const auto chart = sample_scatter();
  const std::string svg = plot::scatter_svg(chart);
  expect_svg_document(svg);
  const auto circles = elements(svg, "circle", "point");
  ASSERT_EQ(circles.size(), chart.points.size()) << svg;
  for (size_t i = 0; i < circles.size(); ++i) {
    EXPECT_EQ(circles[i].attributes.at("data-label"), plot::xml_escape(chart.points[i].label));
    EXPECT_DOUBLE_EQ(number(circles[i], "data-x"), chart.points[i].x);
    EXPECT_DOUBLE_EQ(number(circles[i], "data-y"), chart.points[i].y);
  }
  // Positions are linear in the values (the x axis from 0, so cx is proportional to x), larger y higher up.
  const double px_per_ms = (number(circles[0], "cx") - number(circles[4], "cx")) / (12 - 5);
  const double px_per_db = (number(circles[4], "cy") - number(circles[0], "cy")) / (60 - 30);
  ASSERT_GT(px_per_ms, 0);
  ASSERT_GT(px_per_db, 0);
  const double origin = number(circles[4], "cx") - 5 * px_per_ms;
  for (size_t i = 0; i < circles.size(); ++i) {
    EXPECT_NEAR(number(circles[i], "cx"), origin + chart.points[i].x * px_per_ms, 3e-3) << i;
    EXPECT_NEAR(number(circles[i], "cy"), number(circles[4], "cy") - (chart.points[i].y - 30) * px_per_db, 3e-3) << i;
  }
  // The x axis starts at 0; the y axis spans the values only, from a round tick at or below 30 dB.
  std::vector<double> ticks;
  for (const auto& e : elements(svg, "text", "tick-label")) ticks.push_back(std::strtod(e.text.c_str(), nullptr));
  EXPECT_NE(std::find(ticks.begin(), ticks.end(), 0.0), ticks.end());
  EXPECT_NE(std::find(ticks.begin(), ticks.end(), 30.0), ticks.end());
  EXPECT_NE(std::find(ticks.begin(), ticks.end(), 60.0), ticks.end());
  EXPECT_EQ(std::find(ticks.begin(), ticks.end(), 20.0), ticks.end());

  // Every point is labelled, inside the chart (at 0.6 em a character, as the writer reckons).
  const auto labels = elements(svg, "text", "point-label");
  ASSERT_EQ(labels.size(), chart.points.size());
  const double width = std::strtod(svg.substr(svg.find("width=\"") + 7).c_str(), nullptr);
  for (const auto& label : labels) {
    const double extent = 0.6 * 12 * static_cast<double>(label.text.size());
    const double x = number(label, "x");
    if (label.attributes.at("text-anchor") == "end") {
      EXPECT_GE(x - extent, 0) << label.text;
    } else {
      EXPECT_LE(x + extent, width) << label.text;
    }
  }
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

TEST(BenchPlot, ScatterParetoLinePassesThroughExactlyTheFrontPoints) {
  for (const bool higher_is_better : {true, false}) {
    auto chart = sample_scatter();
    chart.y_higher_is_better = higher_is_better;
    const std::string svg = plot::scatter_svg(chart);
    const auto circles = elements(svg, "circle", "point");
    const auto pareto = elements(svg, "polyline", "pareto");
    ASSERT_EQ(pareto.size(), 1u);
    const auto line = polyline_points(pareto[0].attributes.at("points"));
    const auto front = plot::pareto_front(chart.points, higher_is_better);
    ASSERT_EQ(line.size(), front.size());
    for (size_t k = 0; k < front.size(); ++k) {
      // Written with the same rounding as the circle: equal to the printed digit.
      EXPECT_EQ(line[k].first, number(circles[front[k]], "cx")) << k;
      EXPECT_EQ(line[k].second, number(circles[front[k]], "cy")) << k;
      if (k > 0) {
        EXPECT_GT(line[k].first, line[k - 1].first);
      }
    }
    for (size_t i = 0; i < circles.size(); ++i) {
      const bool on_front = std::find(front.begin(), front.end(), i) != front.end();
      EXPECT_EQ(circles[i].attributes.at("data-pareto"), on_front ? "1" : "0") << chart.points[i].label;
    }
  }
}

TEST(BenchPlot, ScatterEscapesLabels) {
  plot::ScatterChart chart;
  chart.title = "<modes> & \"times\"";
  chart.points = {{"sort <16 bits> & 'fast' \"mode\"", 3, 20}, {"exact", 4, 30}};
  const std::string svg = plot::scatter_svg(chart);
  expect_svg_document(svg);
  const std::string escaped = "sort &lt;16 bits&gt; &amp; &apos;fast&apos; &quot;mode&quot;";
  const auto circles = elements(svg, "circle", "point");
  ASSERT_EQ(circles.size(), 2u);
  EXPECT_EQ(circles[0].attributes.at("data-label"), escaped);
  const auto labels = elements(svg, "text", "point-label");
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].text, escaped);
  EXPECT_EQ(svg.find("<16"), std::string::npos);
  EXPECT_EQ(svg.find("'fast'"), std::string::npos);
  EXPECT_EQ(elements(svg, "text", "title").front().text, "&lt;modes&gt; &amp; &quot;times&quot;");
}

TEST(BenchPlot, ScatterClampsValuesWithoutAPlaceOnTheAxis) {
  const double inf = std::numeric_limits<double>::infinity();
  plot::ScatterChart chart = sample_scatter();
  chart.points.push_back({"reference itself", 14, inf, 7});
  chart.points.push_back({"broken", 6, NAN, 8});
  chart.points.push_back({"no timing", NAN, 35, 9});  // no place on x: left out
  const std::string svg = plot::scatter_svg(chart);
  expect_svg_document(svg);
  const auto circles = elements(svg, "circle", "point");
  ASSERT_EQ(circles.size(), chart.points.size() - 1);
  const auto& identical = circles[7];
  const auto& broken = circles[8];
  EXPECT_EQ(identical.attributes.at("data-label"), "reference itself");
  EXPECT_EQ(identical.attributes.at("data-y"), "inf");
  EXPECT_EQ(broken.attributes.at("data-y"), "nan");
  EXPECT_EQ(svg.find("no timing"), std::string::npos);
  double highest = 1e300;
  double lowest = -1e300;
  for (size_t i = 0; i < 7; ++i) {
    highest = std::min(highest, number(circles[i], "cy"));
    lowest = std::max(lowest, number(circles[i], "cy"));
  }
  EXPECT_LT(number(identical, "cy"), highest);  // above every finite point, on the band past the top tick
  EXPECT_GT(number(broken, "cy"), lowest);
  EXPECT_TRUE(std::isfinite(number(identical, "cy")));

  std::map<std::string, std::string> label_text;
  for (const auto& e : elements(svg, "text", "point-label")) label_text[e.attributes.at("data-label")] = e.text;
  EXPECT_EQ(label_text["reference itself"], "reference itself (identical)");
  EXPECT_EQ(label_text["broken"], "broken (y = nan)");
  EXPECT_EQ(label_text["exact"], "exact");

  // +inf is the best PSNR: the slowest point, but on the front; NaN is not.
  EXPECT_EQ(identical.attributes.at("data-pareto"), "1");
  EXPECT_EQ(broken.attributes.at("data-pareto"), "0");
  const auto line = polyline_points(elements(svg, "polyline", "pareto").at(0).attributes.at("points"));
  ASSERT_FALSE(line.empty());
  EXPECT_EQ(line.back().first, number(identical, "cx"));
  EXPECT_EQ(line.back().second, number(identical, "cy"));

  // Where higher is not better, +inf is not "identical", only clamped.
  chart.y_higher_is_better = false;
  const std::string lower = plot::scatter_svg(chart);
  label_text.clear();
  for (const auto& e : elements(lower, "text", "point-label")) label_text[e.attributes.at("data-label")] = e.text;
  EXPECT_EQ(label_text["reference itself"], "reference itself (y = inf)");

  // Every y unusable, and on a log axis a zero: still a chart, points at the ends of the axis.
  plot::ScatterChart degenerate;
  degenerate.y_scale = plot::Scale::kLog10;
  degenerate.points = {{"zero error", 2, 0}, {"inf", 3, inf}};
  const std::string svg2 = plot::scatter_svg(degenerate);
  expect_svg_document(svg2);
  const auto circles2 = elements(svg2, "circle", "point");
  ASSERT_EQ(circles2.size(), 2u);
  EXPECT_GT(number(circles2[0], "cy"), number(circles2[1], "cy"));
  EXPECT_EQ(svg2.find("nan\""), std::string::npos);  // no coordinate is NaN
}

TEST(BenchPlot, EmptyScatterIsStillADocument) {
  plot::ScatterChart chart;
  chart.title = "nothing";
  const std::string svg = plot::scatter_svg(chart);
  expect_svg_document(svg);
  EXPECT_TRUE(elements(svg, "circle", "point").empty());
  EXPECT_EQ(elements(svg, "polyline", "pareto").size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// --resolutions

TEST(BenchResolutions, AcceptsSizeLists) {
  EXPECT_EQ(parse_resolutions("--resolutions", "1920x1080,1280x720"),
            (std::vector<ImageSize>{{1920, 1080}, {1280, 720}}));
  EXPECT_EQ(parse_resolutions("--resolutions", "64x36"), (std::vector<ImageSize>{{64, 36}}));
  EXPECT_EQ(parse_resolutions("--resolutions", " 320x180 , 1x1,65536x65536"),
            (std::vector<ImageSize>{{320, 180}, {1, 1}, {65536, 65536}}));
  // A size given twice is measured once, in its first place.
  EXPECT_EQ(parse_resolutions("--resolutions", "320x180,640x360,320x180"),
            (std::vector<ImageSize>{{320, 180}, {640, 360}}));
}

TEST(BenchResolutions, RejectsBadSizesNamingFlagAndValue) {
  for (const char* text : {"", "1920", "1920x", "x1080", "0x720", "1280x0", "-5x3", "5x-3", "1920x1080x2",
                           "1920X1080", "12.5x10", "70000x10", "10x65537", "99999999999x1", "abc", "1920x1080,",
                           ",1920x1080", "1920 x 1080", "+5x3", "0x10"}) {
    try {
      parse_resolutions("--resolutions", text);
      ADD_FAILURE() << "accepted '" << text << "'";
    } catch (const UsageError& error) {
      const std::string message = error.what();
      EXPECT_EQ(message.rfind("--resolutions expects WxH sizes", 0), 0u) << message;
      EXPECT_NE(message.find("'" + std::string(text) + "'"), std::string::npos) << message;
    }
  }
  // In a list, the message quotes the bad entry and then the whole list.
  try {
    parse_resolutions("--resolutions", "1920x1080,0x720");
    ADD_FAILURE() << "accepted 0x720";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("got '0x720' in '1920x1080,0x720'"), std::string::npos) << error.what();
  }
}

}  // namespace
