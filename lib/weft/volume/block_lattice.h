#pragma once
/// @file
/// @brief The blocks of a coarse grid, anchored to the cloth rather than to the index lattice
/// (docs/render.md §5 "Coarse grids anchored to the cloth").
///
/// A coarse voxel of f³ fine voxels stands for whatever those voxels hold, so where the blocks
/// fall decides the coarse grid. Anchored at multiples of f in index space, the same cloth stored
/// at another index origin (another tool's lattice, `Grid.from_numpy`'s element 0 at index 0)
/// would get other blocks and render differently. Anchored at the active box's lower corner,
/// the blocks move with the voxels, so a whole-voxel translation changes no coarse value. The
/// window statistics of `weft validate` anchor their blocks the same way (docs/validate.md
/// "Blocks anchored to the cloth").

#include <array>
#include <cstdint>

#include "weft/core/floor_div.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// @brief Coarse index I (per axis) holds the fine voxels [anchor + f·I, anchor + f·I + f); the
/// coarse grid's index 0 starts at the anchor, so its origin is the fine origin moved there.
struct BlockLattice {
  std::array<int, 3> anchor{0, 0, 0};
  int factor = 1;

  /// The coarse index of fine index `fine` along `axis` (⌊(fine − anchor)/f⌋).
  [[nodiscard]] std::int64_t block_of(int axis, std::int64_t fine) const {
    return floor_div(fine - anchor[static_cast<std::size_t>(axis)], factor);
  }
  /// The first fine index of coarse index `block` along `axis`.
  [[nodiscard]] std::int64_t first_voxel(int axis, std::int64_t block) const {
    return anchor[static_cast<std::size_t>(axis)] + block * factor;
  }
  /// World position of the coarse grid's index origin for fine voxels of size `voxel_size` at
  /// `fine_origin` (Grid::origin's convention: index i spans [origin + h·i, origin + h·(i+1))).
  [[nodiscard]] std::array<double, 3> coarse_origin(const std::array<double, 3>& fine_origin, double voxel_size) const {
    return {fine_origin[0] + voxel_size * anchor[0], fine_origin[1] + voxel_size * anchor[1],
            fine_origin[2] + voxel_size * anchor[2]};
  }
};

/// @brief The blocks of `factor` voxels anchored at the lower corner of `active_box` (the fine
/// grid's active box): every active voxel lies in a block of index ≥ 0.
[[nodiscard]] inline BlockLattice block_lattice(const IndexBox& active_box, int factor) {
  return {active_box.min, factor};
}

}  // namespace weft::volume
