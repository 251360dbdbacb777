#pragma once
/// @file
/// @brief Several grids in one .vdb file.

#include <filesystem>
#include <vector>

#include "weft/volume/grid.h"

namespace weft::volume {

/// @brief Checks the structure of a .vdb file before OpenVDB reads it: header, metadata, grid
/// descriptors and each grid's header, with every declared length and offset bounded by the file
/// size. Throws weft::Error naming the file for a truncated or corrupt file (OpenVDB's reader
/// would allocate whatever a length read past the end says: gigabytes for a truncated file).
void check_vdb_file(const std::filesystem::path& path);

/// Writes all `grids` (with their names and metadata) to one .vdb file atomically.
void save_grids(const std::vector<Grid>& grids, const std::filesystem::path& path);

}  // namespace weft::volume
