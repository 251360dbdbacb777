#pragma once
/// @file
/// @brief Fibres (polylines with radius) → sparse OpenVDB grid of fibre volume fraction C.

#include <cstdint>

#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/fibers.h"
#include "weft/core/front_end.h"
#include "weft/core/memory.h"  // default_memory_budget(): what --max-memory defaults to
#include "weft/core/progress.h"
#include "weft/volume/grid.h"

namespace weft::cloth {

/// Half the physical RAM, what `--max-memory` defaults to (weft/core/memory.h; named here too).
using weft::default_memory_budget;

struct VoxelizeOptions {
  double voxel_size = 0.01;            ///< mm, edge of a cubic voxel (index i covers [i·h, (i+1)·h))
  int samples_per_voxel = 4;           ///< quadrature points per voxel edge, along and across each fibre
  std::uint64_t max_memory_bytes = 0;  ///< refuse when the estimate exceeds this; 0 = default_memory_budget()
  /// Under mpirun, fill the leaves on all ranks (dist::run_units, units = ranges of leaves): rank 0
  /// returns the whole grid, the same bytes as one process; other ranks an empty grid and a report
  /// without volumes. Only for callers whose other ranks need no grid (`weft gen`).
  bool spread = false;
  /// Who asked: the memory errors name the budget's option in its words (`--max-memory` or
  /// `max_memory_mb=`; docs/python.md "One set of checks").
  FrontEnd asker = FrontEnd::cli;
};

/// @brief Upper bound of the memory a voxelization will take, computed without allocating it.
struct VoxelizeEstimate {
  std::uint64_t pieces = 0;       ///< fibre pieces (segments cut to ≤ 4 voxels)
  std::uint64_t bin_entries = 0;  ///< (leaf, piece) pairs
  std::uint64_t leaves = 0;       ///< upper bound of 8³ leaf nodes
  std::uint64_t bytes = 0;        ///< upper bound of the peak memory
};
/// Throws weft::Error when the voxel size is invalid or the index range does not fit.
VoxelizeEstimate estimate_voxelize_memory(const FiberSet& fibers, const VoxelizeOptions& options);

/// @brief Deposits every fibre's volume into the voxels it overlaps, as volume fraction C.
///
/// Each segment is a cylinder (no caps, so consecutive segments do not double count). It is
/// integrated by a fixed quadrature: stations at the midpoints of `m` equal slices along the
/// axis and, on each, equal-area rings with points spaced ≤ h/samples_per_voxel. Every point
/// carries the exact volume of its cell of the cylinder, so Σ C·h³ = Σ length·πr² up to float
/// rounding and clamping, for any voxel size; how well the volume is placed voxel by voxel
/// improves with samples_per_voxel. Pieces are binned by the 8³ leaf nodes they touch, each leaf
/// is filled from its bin in parallel (TBB) in bin order, and only touched leaves exist, so the
/// result does not depend on the thread count. Values above 1 (overlapping fibres) clamp to 1
/// and the lost volume is reported. The memory estimate is checked against the budget before
/// any bins or leaves are allocated.
volume::Grid voxelize(const FiberSet& fibers, const VoxelizeOptions& options, VoxelizeReport& report,
                      ProgressSink& progress = null_progress());

}  // namespace weft::cloth
