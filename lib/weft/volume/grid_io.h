#pragma once
/// @file
/// @brief Several grids in one .vdb file.

#include <filesystem>
#include <vector>

#include "weft/volume/grid.h"

namespace weft::volume {

/// @brief Checks the structure of a .vdb file before OpenVDB reads it: header, metadata, grid
/// descriptors, each grid's header, and the whole tree of every float grid (topology, and each
/// leaf's compressed buffer sizes), with every declared length, count, offset and buffer size
/// bounded by the bytes actually there. Throws weft::Error naming the file for a truncated or
/// corrupt file (OpenVDB's reader allocates whatever a length or compressed size in the file
/// says: gigabytes for a truncated or corrupt file). Only float grids of file format 222-224
/// (OpenVDB 3.0 and newer) are checked in full, so only they may be read (Grid::load).
void check_vdb_file(const std::filesystem::path& path);

/// Writes all `grids` (with their names and metadata) to one .vdb file atomically.
void save_grids(const std::vector<Grid>& grids, const std::filesystem::path& path);

}  // namespace weft::volume
