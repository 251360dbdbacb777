#pragma once
/// @file
/// @brief 2D line/marker charts, alone or as a grid of panels, rendered to PNG with VTK's charts
/// (no VTK in this header).

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace weft::viz {

using Rgb = std::array<unsigned char, 3>;

/// How a series' line is drawn. The patterns are drawn by weft (in screen pixels, scaled with the
/// line width), not by VTK's stipple, whose dotted line is a 1 px tick every 8 px.
enum class LineStyle {
  solid,
  dashed,    ///< long dashes
  dotted,    ///< round-ish dots, at least 3 px across
  dash_dot,  ///< dash, dot, dash, ...
  markers,   ///< no line: a marker at each point (circle unless `marker` says otherwise)
};

/// A marker drawn at each point (on top of the line, if any).
enum class Marker { none, circle, square, diamond, cross, plus };

struct Series {
  std::string label;  ///< legend entry; empty: not in the legend
  std::vector<double> x;
  std::vector<double> y;
  Rgb color{0, 0, 0};
  LineStyle style = LineStyle::solid;
  float width = 2.0f;  ///< line width in pixels (markers scale with it)
  Marker marker = Marker::none;
};

/// A shaded region between two curves over the same x (e.g. a measurement +- its standard error),
/// drawn under every series. Points a log axis cannot show are dropped.
struct Band {
  std::string label;  ///< legend entry; empty: not in the legend
  std::vector<double> x;
  std::vector<double> lower;
  std::vector<double> upper;
  Rgb color{0, 0, 0};
  double opacity = 0.25;  ///< in (0, 1]
};

/// Text placed at a data position (e.g. a point's parameter), offset so it does not cover the point.
struct Annotation {
  double x = 0.0;
  double y = 0.0;
  std::string text;
  Rgb color{0, 0, 0};
};

struct Chart {
  std::string title;
  std::string x_label;
  std::string y_label;
  bool log_x = false;
  bool log_y = false;
  std::optional<std::pair<double, double>> x_range;
  std::optional<std::pair<double, double>> y_range;
  std::vector<Series> series;
  /// Vertical dashed marker lines at these x (e.g. a medium boundary).
  std::vector<double> vertical_lines;
  std::vector<Band> bands;
  std::vector<Annotation> annotations;
  /// Size of the picture (alone) or of this panel's cell (in a grid).
  int width = 1000;
  int height = 700;
};

/// Outcome of an attempt to render a picture: pictures need an X display with Debian's VTK.
struct RenderOutcome {
  bool written = false;
  std::string reason;  ///< why not, when !written
};

/// Renders the chart to a PNG (written atomically). Non-finite points, and points a log axis cannot
/// show (<= 0), are dropped and break the line there (no segment is drawn across them). Automatic
/// ranges get a margin so no marker touches the frame. Never throws for a missing display: returns
/// !written and why. Throws weft::Error for an invalid chart or an unwritable target.
RenderOutcome save_chart_png(const Chart& chart, const std::filesystem::path& path);

/// Small multiples: the panels laid out row by row in `columns` columns (the last row may be
/// short), each with its own title, axes and legend, under an optional figure title. Every cell
/// has the size of the largest panel's width x height. Same guarantees as save_chart_png.
RenderOutcome save_chart_grid_png(const std::vector<Chart>& panels, int columns, const std::filesystem::path& path,
                                  const std::string& title = {});

}  // namespace weft::viz
