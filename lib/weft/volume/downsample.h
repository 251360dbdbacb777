#pragma once
/// @file
/// @brief Volume-fraction preserving downsampling of a grid by an integer factor.

#include <array>
#include <optional>

#include "weft/volume/grid.h"

namespace weft::volume {

/// @brief The grid at `factor`× coarser voxels, conserving the amount of what it holds.
///
/// Coarse voxel (I, J, K) covers the fine voxels [a + f·I, a + f·I + f)³ in index space, a the
/// active box's lower corner (blocks anchored to the cloth, volume/block_lattice.h, as `weft fit
/// --block`), and its value is the mean of those f³ fine values,
/// inactive fine voxels counting as 0: Σ_coarse C·(f·h)³ = Σ_fine C·h³ to float rounding, for
/// any extent (blocks straddling the active box are simply partly empty). A coarse voxel is
/// active when any of its fine voxels is. Index 0 at the anchor (origin moved there); voxel size f·h;
/// metadata kept. This is
/// the exponential (RTE) model of the coarse resolution: each coarse voxel a homogeneous medium
/// with the mean concentration. Sums are in double, per block in a fixed order, so the result
/// does not depend on the thread count.
///
/// (`openvdb::tools::resampleToMatch` with a box sampler would interpolate point samples
/// rather than integrate the fine voxels, which does not conserve volume in general.)
///
/// Throws weft::Error for factor < 1 or > 4096, or a grid without active voxels.
[[nodiscard]] Grid downsample(const Grid& fine, int factor);

/// A coarse cell whose value is not the mean of the fine voxels under it.
struct BlockMeanMismatch {
  std::array<int, 3> index{};      ///< the coarse cell
  std::array<double, 3> centre{};  ///< its centre [world length]
  double coarse = 0.0;             ///< the value it holds
  double fine_mean = 0.0;          ///< the mean of the fine voxels under it
};

/// @brief Whether `coarse` holds the block means of `fine`, as downsample and the local fields'
/// mean (`weft fit --block`) compute them: every cell of `coarse` (voxels a whole number f of
/// `fine`'s wide, on `fine`'s voxel corners: the caller checks both) against the mean of the f³
/// fine voxels it covers, inactive voxels counting 0 on both sides (a block of zeros may be left
/// out), to a relative 1e-3. The first cell that differs, in tree order (so the same every run),
/// or nothing. The fields of another cloth, of this cloth elsewhere or of a part of it differ.
/// One pass over `fine`'s active voxels, sums per block in double.
[[nodiscard]] std::optional<BlockMeanMismatch> block_mean_mismatch(const Grid& coarse, const Grid& fine);

}  // namespace weft::volume
