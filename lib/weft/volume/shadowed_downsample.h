#pragma once
/// @file
/// @brief Downsampling that keeps each block's mean directional transmittance: the extinction
/// corrected for sub-block self-shadowing (docs/render.md §6d).

#include <array>

#include "weft/volume/grid.h"

namespace weft::volume {

/// The coarse grids of shadowed_downsample: per axis, and the isotropic combination.
struct ShadowedGrids {
  /// Per axis a: the value whose extinction (scale·value) makes an exponential through the
  /// block along a transmit the fine block's mean transmittance along a.
  std::array<Grid, 3> per_axis;
  /// The mean of the three (the isotropic part, trace/3, of σ(ω) = Σ_a ω_a² σ_a).
  Grid isotropic;
};

/// @brief The grid at `factor`× coarser voxels with the extinction corrected for self-shadowing
/// inside each block (the idea of Loubet & Neyret 2018, derived in docs/render.md §6d).
///
/// Blocks as volume::downsample: coarse voxel (I, J, K) covers the fine voxels [f·I, f·I + f)³
/// in index space, inactive fine voxels count as 0, and a coarse voxel is active when any of
/// its fine voxels is. `scale` turns a value into extinction (σ of a concentration grid, 1 for
/// an extinction grid) and h is the fine voxel size. Along axis a each of the f² fine columns
/// that cross the block has optical depth τ_j = scale·h·Σ_i v_i over its f voxels; the block's
/// mean transmittance is T̄_a = mean_j e^{−τ_j}, and the coarse value along a is the one whose
/// extinction gives it through the block's length f·h:
///   value_a = −ln(T̄_a) / (scale · f · h).
/// ln T̄_a is log1p(mean expm1(−τ_j)) while T̄_a ≥ 1/2 (no cancellation for thin blocks) and a
/// log-sum-exp otherwise (no underflow for opaque ones), so T̄_a → 0 is never a division by 0.
/// By Jensen's inequality T̄_a ≥ e^{−mean τ}, so 0 ≤ value_a ≤ the block's mean value (what
/// downsample stores): the mean is the cap, applied against rounding. When every column has
/// the same depth there is nothing to correct and value_a is exactly the block mean, so a
/// block of uniform value equals volume::downsample's coarse voxel bit for bit.
///
/// Physical, hence independent of the voxel size for the same cloth (refining h by 2 and
/// doubling the factor gives the same grid), of the world origin and of the index origin: like
/// downsample, blocks are anchored to the cloth (volume/block_lattice.h). Origin, voxel size f·h
/// and metadata as downsample
/// (`weft:downsample_factor`), plus `weft:downsample_rule` = `shadowed` and the scale used
/// (`weft:shadow_scale`). Blocks are independent work units, so the result does not depend on
/// the thread count.
///
/// Throws weft::Error for factor < 1 or > 4096, scale not finite and > 0, or a grid without
/// active voxels.
[[nodiscard]] ShadowedGrids shadowed_downsample(const Grid& fine, int factor, double scale);

}  // namespace weft::volume
