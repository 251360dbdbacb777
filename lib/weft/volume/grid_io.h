#pragma once
/// @file
/// @brief Several grids in one .vdb file.

#include <cstdint>
#include <filesystem>
#include <string>
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

/// Writes all `grids` (with their names and metadata) to one .vdb file atomically. Throws
/// weft::Error, writing nothing, when Grid::load would refuse a grid for what the writing did
/// (a value beyond 65504 in a grid stored as half: require_writable).
void save_grids(const std::vector<Grid>& grids, const std::filesystem::path& path);

/// What one grid of a file holds in memory.
struct GridCount {
  std::string name;
  std::uint64_t active_voxels = 0;  ///< active voxels, tiles counted per voxel
  std::uint64_t tree_bytes = 0;     ///< OpenVDB's Tree::memUsage (nodes, masks, values)
  int value_bytes = 4;              ///< bytes a value takes in the file: 2 when stored as half
};

/// @brief Every float grid of a .vdb file with its active voxels and tree bytes, in file order:
/// what a file costs, every channel counted (docs/render.md §6e). The values are not checked
/// (Grid::load refuses the +∞ α, β of exponential blocks; they still cost 4 bytes each). Throws
/// weft::Error naming the file when it is missing or not a valid OpenVDB file (check_vdb_file).
[[nodiscard]] std::vector<GridCount> count_grids(const std::filesystem::path& path);

}  // namespace weft::volume
