#pragma once
/// @file
/// @brief A 3D picture of a voxel grid (an isosurface of its values) with optional arrows, to PNG.

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "weft/viz/chart.h"
#include "weft/volume/grid.h"

namespace weft::viz {

struct Arrow {
  std::array<double, 3> direction;  ///< world direction (need not be unit)
  std::array<unsigned char, 3> color;
  std::string label;
};

struct VolumeView {
  std::string title;
  std::vector<Arrow> arrows;  ///< drawn from outside the grid's bounds towards its centre; labels in a key
  /// A second panel (right) looking straight down -z, orthographic: holes through a cloth in the
  /// xy plane show as background there even when the oblique view hides them.
  bool top_view = true;
  int width = 1400;
  int height = 700;
};

/// Renders the grid's active region as a lit isosurface (at a third of a high percentile of the
/// values, on the grid box-filtered to a display budget), in a three-quarter view with the arrows
/// and, if asked, a top view. Labels never overlap geometry: they go in a key below the view.
/// Never throws for a missing display: returns !written and why.
RenderOutcome save_volume_png(const volume::Grid& grid, const VolumeView& view, const std::filesystem::path& path);

}  // namespace weft::viz
