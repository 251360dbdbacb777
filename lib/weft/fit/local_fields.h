#pragma once
/// @file
/// @brief What local statistic fields (fit.h: local_fields) will cost, known before they are
/// computed: `weft fit --block` checks its block size and refuses an estimate over the budget
/// before it spends anything.

#include <cstdint>

#include "weft/volume/grid.h"

namespace weft::fit {

/// Largest block edge local_fields accepts (voxels): the edge of OpenVDB's root tiles, and small
/// enough that block index × edge stays inside int coordinates.
inline constexpr int kMaxLocalBlock = 4096;

/// Throws weft::Error naming the block size unless 1 ≤ block ≤ kMaxLocalBlock.
void check_local_block(int block);

/// @brief Upper bounds of the work and memory of local_fields(grid, block), from the leaf nodes
/// alone (O(leaves), nothing allocated per voxel or per block).
///
/// The fields are computed block by block from the grid's own leaves: a block's columns are
/// accumulated densely only for blocks of at most 64³ voxels and in a hash map of its non-empty
/// columns otherwise, so memory grows with the grid's active voxels and the number of blocks,
/// never with B³ (before: a dense B³ copy per block and thread, 8 GB per thread at B = 1000).
struct LocalFieldsEstimate {
  std::uint64_t leaf_entries = 0;  ///< (block, leaf or tile) pairs the blocks are built from
  std::uint64_t blocks = 0;        ///< upper bound of the blocks with data
  std::uint64_t bytes = 0;         ///< upper bound of the peak memory beyond the input grid
};
[[nodiscard]] LocalFieldsEstimate estimate_local_fields(const volume::Grid& grid, int block);

}  // namespace weft::fit
