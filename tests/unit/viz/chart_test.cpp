#include "weft/viz/chart.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "image_probe.h"
#include "weft/core/error.h"

namespace weft::viz {
namespace {

Series constant(const std::string& label, double y, std::array<unsigned char, 3> colour, LineStyle style) {
  Series s;
  s.label = label;
  for (int i = 0; i <= 50; ++i) {
    s.x.push_back(i / 50.0);
    s.y.push_back(y);
  }
  s.color = colour;
  s.style = style;
  s.width = 3.0f;
  return s;
}

TEST(Chart, WritesPngOfRequestedSizeWithSeriesWhereTheyBelong) {
  const auto dir = test::scratch_dir("chart_size");
  Chart chart;
  chart.title = "two levels";
  chart.x_label = "depth";
  chart.y_label = "T";
  chart.width = 640;
  chart.height = 480;
  chart.y_range = std::make_pair(0.0, 1.0);
  chart.series.push_back(constant("high", 0.8, {255, 0, 0}, LineStyle::solid));
  chart.series.push_back(constant("low", 0.2, {0, 0, 255}, LineStyle::dashed));
  const auto png = dir / "chart.png";
  const RenderOutcome out = save_chart_png(chart, png);
  ASSERT_TRUE(out.written) << out.reason;
  const test::Image image = test::read_png(png);
  ASSERT_TRUE(image.data) << "not a PNG VTK can read";
  EXPECT_EQ(image.width, 640);
  EXPECT_EQ(image.height, 480);
  const auto red = test::find_colour(image, {255, 0, 0});
  const auto blue = test::find_colour(image, {0, 0, 255});
  // A 3 px line across most of the plot width: hundreds of pixels at least.
  EXPECT_GT(red.count, 300);
  EXPECT_GT(blue.count, 150);
  // PNG rows read by VTK run bottom-up: y = 0.8 sits well above y = 0.2.
  EXPECT_GT(red.mean_row, blue.mean_row + 0.3 * image.height);
  // The background is white, so most pixels are.
  EXPECT_GT(test::find_colour(image, {255, 255, 255}, 5).count, image.width * image.height / 2);
  test::cleanup(dir);
}

TEST(Chart, LogAxesDropNonPositiveValues) {
  const auto dir = test::scratch_dir("chart_log");
  Chart chart;
  chart.log_x = true;
  chart.log_y = true;
  chart.width = 500;
  chart.height = 400;
  Series s;
  s.label = "power law with zeros";
  s.color = {0, 160, 0};
  for (int i = -5; i <= 40; ++i) {
    s.x.push_back(i <= 0 ? double(i) : std::pow(10.0, i / 10.0));
    s.y.push_back(i % 7 == 0 ? 0.0 : (i < 0 ? -1.0 : std::pow(10.0, -i / 10.0)));
  }
  s.x.push_back(std::nan(""));
  s.y.push_back(1.0);
  chart.series.push_back(s);
  chart.vertical_lines = {-1.0, 0.0, 10.0};
  const auto png = dir / "log.png";
  const RenderOutcome out = save_chart_png(chart, png);
  ASSERT_TRUE(out.written) << out.reason;
  const test::Image image = test::read_png(png);
  ASSERT_TRUE(image.data);
  EXPECT_EQ(image.width, 500);
  EXPECT_GT(test::find_colour(image, {0, 160, 0}, 30).count, 100);
  test::cleanup(dir);
}

TEST(Chart, MarkersAndVerticalLinesAreDrawn) {
  const auto dir = test::scratch_dir("chart_markers");
  Chart chart;
  chart.width = 600;
  chart.height = 400;
  Series s = constant("samples", 0.5, {200, 0, 200}, LineStyle::markers);
  chart.series.push_back(s);
  chart.vertical_lines = {0.5};
  const auto png = dir / "markers.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  EXPECT_GT(test::find_colour(image, {200, 0, 200}, 30).count, 200);
  // The dashed marker line is drawn in mid grey at x = 0.5, i.e. near the middle of the plot.
  // Text is grey at its antialiased edges too, so look for the column richest in grey.
  std::vector<int> per_column(static_cast<std::size_t>(image.width), 0);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto c = image.rgb(x, y);
      if (std::abs(c[0] - 90) <= 25 && std::abs(c[1] - 90) <= 25 && std::abs(c[2] - 90) <= 25) {
        ++per_column[static_cast<std::size_t>(x)];
      }
    }
  }
  const auto best = std::max_element(per_column.begin(), per_column.end());
  EXPECT_GT(*best, image.height / 4) << "no dashed vertical line";
  EXPECT_NEAR(static_cast<double>(best - per_column.begin()), image.width / 2.0, 0.1 * image.width);
  test::cleanup(dir);
}

// The project's main figure (cf. supplement Fig. S.13): log T against depth, measured curves
// solid, model curves dotted, one colour per direction.
TEST(Chart, TransmittanceFigureShowsSolidAndDottedCurvesOnLogAxis) {
  const auto dir = test::scratch_dir("chart_s13");
  Chart chart;
  chart.title = "Transmittance through cloth";
  chart.x_label = "depth t [mm]";
  chart.y_label = "T(t)";
  chart.log_y = true;
  const std::array<std::array<unsigned char, 3>, 3> colours{{{220, 30, 30}, {30, 140, 30}, {30, 60, 220}}};
  const std::array<double, 3> alpha{0.6, 1.5, 4.0};
  for (std::size_t d = 0; d < 3; ++d) {
    Series measured;
    Series model;
    measured.label = "measured " + std::string(1, "xyz"[d]);
    model.label = "gamma fit " + std::string(1, "xyz"[d]);
    for (int i = 0; i <= 200; ++i) {
      const double t = 5.0 * i / 200.0;
      measured.x.push_back(t);
      model.x.push_back(t);
      model.y.push_back(std::pow(1.0 + 3.0 * t / alpha[d], -alpha[d]));
      measured.y.push_back(model.y.back() * (1.0 + 0.05 * std::sin(7.0 * t)));
    }
    measured.color = model.color = colours[d];
    model.style = LineStyle::dotted;
    chart.series.push_back(measured);
    chart.series.push_back(model);
  }
  chart.series.push_back(Series{"exponential", {0.0, 5.0}, {1.0, std::exp(-15.0)}, {0, 0, 0}, LineStyle::dashed, 2.0f});
  chart.vertical_lines = {2.5};
  const auto png = dir / "s13.png";
  const RenderOutcome out = save_chart_png(chart, png);
  ASSERT_TRUE(out.written) << out.reason;
  const test::Image image = test::read_png(png);
  ASSERT_EQ(image.width, chart.width);
  ASSERT_EQ(image.height, chart.height);
  for (const auto& c : colours) EXPECT_GT(test::find_colour(image, {c[0], c[1], c[2]}, 30).count, 400);
  test::cleanup(dir);
}

TEST(Chart, LegendAvoidsTheCurves) {
  const auto dir = test::scratch_dir("chart_legend");
  Chart chart;
  chart.width = 600;
  chart.height = 450;
  Series diagonal;
  diagonal.label = "rising line";
  diagonal.color = {255, 0, 0};
  for (int i = 0; i <= 20; ++i) {
    diagonal.x.push_back(i / 20.0);
    diagonal.y.push_back(i / 20.0);
  }
  chart.series.push_back(diagonal);
  const auto png = dir / "legend.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  // The curve crosses the top-right and bottom-left corners, so the legend's black text and
  // frame belong in the top left (rows run bottom-up).
  auto dark_in = [&](double x0, double x1) {
    long n = 0;
    for (int y = static_cast<int>(0.7 * image.height); y < image.height; ++y) {
      for (int x = static_cast<int>(x0 * image.width); x < static_cast<int>(x1 * image.width); ++x) {
        const auto c = image.rgb(x, y);
        if (c[0] < 80 && c[1] < 80 && c[2] < 80) ++n;
      }
    }
    return n;
  };
  const long top_left = dark_in(0.06, 0.45);  // right of the y axis labels
  const long top_right = dark_in(0.55, 0.94);
  EXPECT_GT(top_left, 60);  // frame alone: ~2 x (80 + 20) px
  EXPECT_LT(top_right, top_left / 4);
  test::cleanup(dir);
}

TEST(Chart, MismatchedSeriesIsAnError) {
  const auto dir = test::scratch_dir("chart_bad");
  Chart chart;
  Series s;
  s.label = "broken";
  s.x = {1, 2, 3};
  s.y = {1, 2};
  chart.series.push_back(s);
  EXPECT_THROW(save_chart_png(chart, dir / "bad.png"), weft::Error);
  Chart ranged;
  ranged.log_y = true;
  ranged.y_range = std::make_pair(0.0, 1.0);
  EXPECT_THROW(save_chart_png(ranged, dir / "bad.png"), weft::Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  test::cleanup(dir);
}

TEST(Chart, UnwritableTargetThrowsAndLeavesNoFile) {
  const auto dir = test::scratch_dir("chart_unwritable");
  Chart chart;
  chart.series.push_back(constant("a", 0.5, {255, 0, 0}, LineStyle::solid));
  EXPECT_THROW(save_chart_png(chart, dir / "missing-folder" / "c.png"), weft::Error);
  // A folder where the picture should go: the rename fails after rendering.
  std::filesystem::create_directory(dir / "occupied.png");
  EXPECT_THROW(save_chart_png(chart, dir / "occupied.png"), weft::Error);
  std::vector<std::filesystem::path> left;
  for (const auto& e : std::filesystem::directory_iterator(dir)) left.push_back(e.path().filename());
  ASSERT_EQ(left.size(), 1U);
  EXPECT_EQ(left[0], "occupied.png");
  EXPECT_TRUE(std::filesystem::is_directory(dir / "occupied.png"));
  test::cleanup(dir);
}

}  // namespace
}  // namespace weft::viz
