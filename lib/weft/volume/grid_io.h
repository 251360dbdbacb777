#pragma once
/// @file
/// @brief Several grids in one .vdb file.

#include <filesystem>
#include <vector>

#include "weft/volume/grid.h"

namespace weft::volume {

/// Writes all `grids` (with their names and metadata) to one .vdb file atomically.
void save_grids(const std::vector<Grid>& grids, const std::filesystem::path& path);

}  // namespace weft::volume
