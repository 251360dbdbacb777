#pragma once
/// @file
/// @brief A 3D picture of a voxel grid (volume rendering) with optional arrows, to PNG.

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
  std::vector<Arrow> arrows;  ///< drawn from outside the grid's bounds towards its centre
  int width = 1000;
  int height = 800;
};

/// Renders the grid's active region by volume rendering (values as opacity/colour).
/// Never throws for a missing display: returns !written and why.
RenderOutcome save_volume_png(const volume::Grid& grid, const VolumeView& view, const std::filesystem::path& path);

}  // namespace weft::viz
