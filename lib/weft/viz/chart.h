#pragma once
/// @file
/// @brief 2D line/marker charts rendered to PNG with VTK's charts (no VTK in this header).

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace weft::viz {

enum class LineStyle { solid, dashed, dotted, markers };

struct Series {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  std::array<unsigned char, 3> color{0, 0, 0};
  LineStyle style = LineStyle::solid;
  float width = 2.0f;
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
  int width = 1000;
  int height = 700;
};

/// Outcome of an attempt to render a picture: pictures need an X display with Debian's VTK.
struct RenderOutcome {
  bool written = false;
  std::string reason;  ///< why not, when !written
};

/// Renders the chart to a PNG (written atomically). Non-positive values on a log axis are
/// dropped from their series. Never throws for a missing display: returns !written and why.
/// Throws weft::Error for an unwritable target.
RenderOutcome save_chart_png(const Chart& chart, const std::filesystem::path& path);

}  // namespace weft::viz
