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

TEST(Chart, ALongTitleWrapsInsideThePicture) {
  // accuracy_time.png's title ran off both edges. A title several times the width of
  // the chart wraps: no dark pixel in the outer columns of the title band, and ink on more rows.
  const auto dir = test::scratch_dir("chart_long_title");
  auto render = [&](const std::string& title, const std::string& name) {
    Chart chart;
    chart.title = title;
    chart.x_label = "x";
    chart.y_label = "y";
    chart.width = 500;
    chart.height = 400;
    chart.series.push_back(constant("a", 0.5, {255, 0, 0}, LineStyle::solid));
    const RenderOutcome out = save_chart_png(chart, dir / name);
    EXPECT_TRUE(out.written) << out.reason;
    return test::read_png(dir / name);
  };
  const test::Image long_title =
      render("plain cloth, 4x4 yarns: accuracy vs time (labels: grid coarsening / ray fraction; dashed: Pareto fronts)",
             "long.png");
  const test::Image short_title = render("short", "short.png");
  ASSERT_TRUE(long_title.data && short_title.data);
  // In the top third: rows with dark ink between 25 % and 75 % of the width (where the title is
  // and the axes are not), and dark ink in the 4 outer columns.
  auto title_rows = [](const test::Image& im, int* edge_ink) {
    int rows = 0;
    *edge_ink = 0;
    for (int y = im.height - 1; y >= im.height - im.height / 3; --y) {
      bool ink = false;
      for (int x = 0; x < im.width; ++x) {
        const auto c = im.rgb(x, y);
        if (c[0] < 100 && c[1] < 100 && c[2] < 100) {
          if (x > im.width / 4 && x < 3 * im.width / 4) ink = true;
          if (x < 4 || x >= im.width - 4) ++*edge_ink;
        }
      }
      rows += ink ? 1 : 0;
    }
    return rows;
  };
  int edge_long = 0;
  int edge_short = 0;
  const int rows_long = title_rows(long_title, &edge_long);
  const int rows_short = title_rows(short_title, &edge_short);
  EXPECT_EQ(edge_long, 0) << "the title touches the picture's edges";
  EXPECT_GT(rows_long, 2 * rows_short) << "the long title did not wrap onto more lines";
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

TEST(Chart, ALonePointOfALineIsDrawnAsItsMarker) {
  // A study at one factor gives each model one point: no line to draw (VTK refuses and logs an
  // error), so the point is drawn as a marker instead of disappearing.
  const auto dir = test::scratch_dir("chart_lone_point");
  Chart chart;
  chart.width = 600;
  chart.height = 400;
  Series lone;
  lone.label = "";  // no legend entry: its swatch would be the only purple
  lone.x = {0.5};
  lone.y = {0.5};
  lone.color = {200, 0, 200};
  lone.style = LineStyle::solid;
  lone.width = 3.0f;
  chart.series.push_back(lone);
  chart.series.push_back(constant("other", 0.2, {0, 120, 0}, LineStyle::solid));
  chart.x_range = std::make_pair(0.0, 1.0);
  chart.y_range = std::make_pair(0.0, 1.0);
  const auto png = dir / "lone.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  EXPECT_GT(test::find_colour(image, {200, 0, 200}, 30).count, 20);
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

// Each style leaves a visible trace: a dotted line used to be a 1 px tick every 8 px.
TEST(Chart, EveryLineStyleIsClearlyVisible) {
  const auto dir = test::scratch_dir("chart_styles");
  Chart chart;
  chart.width = 700;
  chart.height = 500;
  chart.y_range = std::make_pair(0.0, 1.0);
  const std::array<std::pair<LineStyle, std::array<unsigned char, 3>>, 4> styles{
      {{LineStyle::solid, {255, 0, 0}},
       {LineStyle::dashed, {0, 0, 255}},
       {LineStyle::dotted, {0, 160, 0}},
       {LineStyle::dash_dot, {200, 0, 200}}}};
  for (std::size_t k = 0; k < styles.size(); ++k) {
    Series s = constant("", 0.2 + 0.2 * static_cast<double>(k), styles[k].second, styles[k].first);
    s.width = 2.0f;
    chart.series.push_back(s);
  }
  const auto png = dir / "styles.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  const auto solid = test::coverage(image, {255, 0, 0});
  ASSERT_GT(solid.pixels, 500);  // a 2 px line across ~600 px
  for (std::size_t k = 1; k < styles.size(); ++k) {
    const auto& c = styles[k].second;
    const auto cov = test::coverage(image, {c[0], c[1], c[2]});
    // At least a third of the solid line's ink, spread over most of its columns.
    EXPECT_GT(cov.pixels, solid.pixels / 3) << "style " << k;
    EXPECT_GT(cov.columns, solid.columns / 4) << "style " << k;  // VTK's dotted: 1/8
    EXPECT_LT(cov.pixels, solid.pixels * 2) << "style " << k;
  }
  test::cleanup(dir);
}

// Empty bins (zeros on a log axis) and NaNs break the line: nothing is drawn across the gap.
TEST(Chart, LinesBreakAtPointsTheAxisCannotShow) {
  const auto dir = test::scratch_dir("chart_gap");
  Chart chart;
  chart.width = 600;
  chart.height = 400;
  chart.log_y = true;
  chart.x_range = std::make_pair(0.0, 1.0);
  chart.y_range = std::make_pair(0.01, 1.0);
  Series s;
  s.color = {255, 0, 0};
  s.width = 3.0f;
  for (int i = 0; i <= 100; ++i) {
    s.x.push_back(i / 100.0);
    // Zero from 0.3 to 0.5, NaN from 0.5 to 0.7: two gaps side by side.
    s.y.push_back(i > 30 && i < 50 ? 0.0 : (i >= 50 && i < 70 ? std::nan("") : 0.1));
  }
  chart.series.push_back(s);
  const auto png = dir / "gap.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  const auto all = test::coverage(image, {255, 0, 0});
  EXPECT_GT(all.pixels, 400);
  // The plot spans roughly 10 % .. 97 % of the width: x = 0.5 sits near 0.53.
  const auto gap = test::coverage(image, {255, 0, 0}, 30, {0.42, 0.0, 0.62, 1.0});
  EXPECT_EQ(gap.pixels, 0) << "a line crosses the empty bins";
  test::cleanup(dir);
}

// A shaded band (measurement +- standard error) under the curves, on a log axis.
TEST(Chart, BandIsShadedBetweenItsBoundsOnALogAxis) {
  const auto dir = test::scratch_dir("chart_band");
  Chart chart;
  chart.width = 600;
  chart.height = 400;
  chart.log_y = true;
  chart.x_range = std::make_pair(0.0, 1.0);
  chart.y_range = std::make_pair(1e-3, 1.0);
  Band band;
  band.label = "+- stderr";
  band.color = {0, 0, 255};
  band.opacity = 0.3;
  for (int i = 0; i <= 20; ++i) {
    band.x.push_back(i / 20.0);
    band.lower.push_back(0.01);
    band.upper.push_back(0.1);
  }
  chart.bands.push_back(band);
  const auto png = dir / "band.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  // 30 % blue over white.
  const std::array<int, 3> shade{179, 179, 255};
  const auto cov = test::coverage(image, shade, 12);
  // One decade of three, across the plot: about a third of the plot area (~0.85 x 0.75 of it).
  const double plot_area = 0.85 * 0.75 * image.width * image.height;
  EXPECT_GT(cov.pixels, 0.25 * plot_area);
  EXPECT_LT(cov.pixels, 0.45 * plot_area);
  // In the middle third vertically (log scale: 1e-2..1e-1 of 1e-3..1).
  const auto top = test::coverage(image, shade, 12, {0.2, 0.0, 0.9, 0.25});
  EXPECT_LT(top.pixels, cov.pixels / 20);
  test::cleanup(dir);
}

// Automatic ranges leave a margin: markers at the data's extremes are drawn whole.
TEST(Chart, AutomaticRangesKeepMarkersOffTheFrame) {
  const auto dir = test::scratch_dir("chart_margin");
  Chart chart;
  chart.width = 600;
  chart.height = 450;
  chart.log_x = true;
  Series corners{"", {1.0, 1.0, 100.0, 100.0}, {0.0, 1.0, 0.0, 1.0}, {255, 0, 0}, LineStyle::markers, 3.0f};
  Series centre{"", {10.0}, {0.5}, {0, 0, 255}, LineStyle::markers, 3.0f};
  chart.series = {corners, centre};
  const auto png = dir / "margin.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  const auto one = test::coverage(image, {0, 0, 255});
  const auto four = test::coverage(image, {255, 0, 0});
  ASSERT_GT(one.pixels, 20);
  // Markers cut by the frame would show a quarter each (four ~ one).
  EXPECT_GT(four.pixels, 3.5 * static_cast<double>(one.pixels));
  test::cleanup(dir);
}

TEST(Chart, AnnotationsAreWrittenNextToTheirPoints) {
  const auto dir = test::scratch_dir("chart_annotation");
  Chart chart;
  chart.width = 600;
  chart.height = 450;
  chart.x_range = std::make_pair(0.0, 1.0);
  chart.y_range = std::make_pair(0.0, 1.0);
  chart.series.push_back(Series{"", {0.25}, {0.25}, {0, 0, 0}, LineStyle::markers, 2.0f, Marker::square});
  chart.annotations.push_back({0.25, 0.25, "factor 4", {0, 170, 0}});
  chart.annotations.push_back({0.99, 0.99, "at the corner", {200, 0, 200}});
  const auto png = dir / "annotation.png";
  ASSERT_TRUE(save_chart_png(chart, png).written);
  const test::Image image = test::read_png(png);
  // The text sits up-right of (0.25, 0.25): in the lower-left quarter of the picture.
  const auto near = test::coverage(image, {0, 170, 0}, 40, {0.15, 0.5, 0.6, 0.85});
  const auto all = test::coverage(image, {0, 170, 0}, 40);
  EXPECT_GT(near.pixels, 30);
  EXPECT_EQ(near.pixels, all.pixels);
  // Near the top right it is moved inside the plot (left and below its point), not cut off.
  const auto corner = test::coverage(image, {200, 0, 200}, 40, {0.45, 0.0, 1.0, 0.3});
  EXPECT_GT(corner.pixels, 40);
  test::cleanup(dir);
}

// Small multiples: each panel's series in its own cell, each panel with its own legend.
TEST(ChartGrid, PanelsAreLaidOutRowByRow) {
  const auto dir = test::scratch_dir("chart_grid");
  std::vector<Chart> panels;
  const std::array<std::array<unsigned char, 3>, 3> colours{{{255, 0, 0}, {0, 0, 255}, {0, 160, 0}}};
  for (std::size_t k = 0; k < colours.size(); ++k) {
    Chart c;
    c.title = "panel " + std::to_string(k);
    c.width = 400;
    c.height = 300;
    c.y_range = std::make_pair(0.0, 1.0);
    c.series.push_back(constant("series " + std::to_string(k), 0.5, colours[k], LineStyle::solid));
    panels.push_back(c);
  }
  const auto png = dir / "grid.png";
  const RenderOutcome out = save_chart_grid_png(panels, 2, png, "three panels");
  ASSERT_TRUE(out.written) << out.reason;
  const test::Image image = test::read_png(png);
  ASSERT_EQ(image.width, 800);
  EXPECT_GT(image.height, 600);  // two rows and the figure title
  EXPECT_LT(image.height, 700);
  const std::array<test::Region, 3> cells{{{0.0, 0.0, 0.5, 0.55}, {0.5, 0.0, 1.0, 0.55}, {0.0, 0.55, 0.5, 1.0}}};
  for (std::size_t k = 0; k < colours.size(); ++k) {
    const std::array<int, 3> c{colours[k][0], colours[k][1], colours[k][2]};
    const auto inside = test::coverage(image, c, 30, cells[k]);
    const auto all = test::coverage(image, c, 30);
    EXPECT_GT(inside.columns, 250) << "panel " << k;  // a line across the panel
    EXPECT_EQ(inside.pixels, all.pixels) << "panel " << k << " leaks into another cell";
  }
  // The fourth cell is empty: white.
  const auto empty_cell = test::coverage(image, {255, 255, 255}, 3, {0.52, 0.6, 0.98, 0.98});
  const double cell_px = 0.46 * 0.38 * image.width * image.height;
  EXPECT_GT(empty_cell.pixels, 0.99 * cell_px);
  EXPECT_THROW(save_chart_grid_png({}, 2, dir / "none.png"), weft::Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "none.png"));
  EXPECT_THROW(save_chart_grid_png(panels, 0, dir / "none.png"), weft::Error);
  test::cleanup(dir);
}

// The shape of validate's transmittance.png: one panel per axis with the ground truth and its
// standard-error band, the gamma law and other models, the exponential; every series must show.
TEST(ChartGrid, TransmittancePanelsShowEverySeriesInTheirCell) {
  const auto dir = test::scratch_dir("chart_grid_t");
  struct Style {
    Rgb colour;
    LineStyle style;
  };
  const std::array<Style, 5> styles{{{{0, 0, 0}, LineStyle::solid},
                                     {{220, 30, 30}, LineStyle::dotted},
                                     {{30, 150, 40}, LineStyle::dashed},
                                     {{30, 60, 220}, LineStyle::dash_dot},
                                     {{140, 40, 180}, LineStyle::dashed}}};
  std::vector<Chart> panels;
  const std::array<double, 3> alpha{0.6, 1.5, 4.0};
  for (std::size_t d = 0; d < 3; ++d) {
    Chart c;
    c.title = std::string("beam +") + "xyz"[d];
    c.x_label = "depth t [mm]";
    c.y_label = "T(t)";
    c.log_y = true;
    c.width = 520;
    c.height = 420;
    c.x_range = std::make_pair(0.0, 1.0);
    c.y_range = std::make_pair(1e-4, 1.2);
    Band band{"ground truth +- stderr", {}, {}, {}, {120, 120, 120}, 0.3};
    std::array<Series, 5> curves;
    const std::array<std::string, 5> names{"ground truth", "gamma law", "model A", "model B", "exponential"};
    for (std::size_t k = 0; k < curves.size(); ++k) {
      curves[k].label = names[k];
      curves[k].color = styles[k].colour;
      curves[k].style = styles[k].style;
    }
    for (int i = 0; i <= 100; ++i) {
      const double t = i / 100.0;
      const double truth = std::pow(1.0 + 6.0 * t / alpha[d], -alpha[d]);
      band.x.push_back(t);
      band.lower.push_back(truth * 0.8);
      band.upper.push_back(truth * 1.25);
      const std::array<double, 5> ys{truth, truth * (1.0 + 2.0 * t), truth * std::exp(-2.0 * t),
                                     truth * std::exp(-4.0 * t), std::exp(-8.0 * t)};
      for (std::size_t k = 0; k < curves.size(); ++k) {
        curves[k].x.push_back(t);
        curves[k].y.push_back(ys[k]);
      }
    }
    c.bands.push_back(band);
    c.series.assign(curves.begin(), curves.end());
    panels.push_back(c);
  }
  const auto png = dir / "transmittance.png";
  ASSERT_TRUE(save_chart_grid_png(panels, 3, png, "Transmittance through cloth").written);
  const test::Image image = test::read_png(png);
  ASSERT_EQ(image.width, 3 * 520);
  for (std::size_t d = 0; d < 3; ++d) {
    const test::Region cell{d / 3.0, 0.0, (d + 1) / 3.0, 1.0};
    for (std::size_t k = 0; k < styles.size(); ++k) {
      const auto& c = styles[k].colour;
      const auto cov = test::coverage(image, {c[0], c[1], c[2]}, 30, cell);
      // Across a good part of the panel (the legend sample alone is ~40 px; the plot ~430; dots 40 %).
      EXPECT_GT(cov.columns, 520 / 6) << "panel " << d << " series " << k;
    }
    // The band's grey at 30 % over white.
    EXPECT_GT(test::coverage(image, {214, 214, 214}, 8, cell).pixels, 1500) << "panel " << d;
  }
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
  Chart banded;
  banded.bands.push_back(Band{"short", {0, 1}, {0.1}, {0.2, 0.3}, {0, 0, 0}, 0.3});
  EXPECT_THROW(save_chart_png(banded, dir / "bad.png"), weft::Error);
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
