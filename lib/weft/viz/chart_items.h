#pragma once
/// @file
/// @brief Internal to weft_viz: the chart items VTK lacks (patterned lines that stay readable,
/// text at data positions, text at pixel positions). VTK only in chart_items.cpp.

#include <array>
#include <string>
#include <vector>

class vtkChartXY;
class vtkContextScene;
class vtkPlot;

namespace weft::viz::detail {

/// On/off lengths in pixels, repeating, starting "on".
using DashPattern = std::vector<float>;

/// The "on" pieces of a polyline (x0 y0 x1 y1 ..., pixels) under a repeating dash pattern, clipped
/// to the box [x_lo, x_hi] x [y_lo, y_hi]: pairs of end points, 4 floats per piece.
std::vector<float> dash_polyline(const std::vector<float>& xy, const DashPattern& pattern,
                                 const std::array<float, 4>& box);

/// A line plot added to `chart` whose line (and legend sample) follows `pattern` (empty: solid).
vtkPlot* add_pattern_line(vtkChartXY& chart, const DashPattern& pattern);

/// Text drawn at data positions of `chart`, offset up-right of each point (up-left near the right
/// edge of the plot), in `size` px. Returns the plot (for its table input).
vtkPlot* add_annotations(vtkChartXY& chart, std::vector<std::string> texts,
                         std::vector<std::array<unsigned char, 3>> colors, int size);

/// Text at a pixel position of the scene, centred horizontally on x, its top at y.
void add_scene_title(vtkContextScene& scene, float x, float y, const std::string& text, int size);

}  // namespace weft::viz::detail
