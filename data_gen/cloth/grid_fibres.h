#pragma once
/// @file
/// @brief The fibres behind a grid: a generated cloth's fibres as geometry for exact ray
/// intersection (weft/fibres), and the fibres of a grid written by `weft gen`, regenerated from
/// the cloth spec its provenance records (docs/validate.md §Fibre ground truth).

#include <array>
#include <string>

#include "data_gen/cloth/fibers.h"
#include "weft/core/progress.h"
#include "weft/fibres/fibre_set.h"
#include "weft/volume/grid.h"

namespace weft::cloth {

/// The polylines and radii of `fibers` (ids dropped).
[[nodiscard]] fibres::FibreSet fibre_geometry(const FiberSet& fibers);

/// Whether the grid records the cloth it was generated from (metadata "generator").
[[nodiscard]] bool grid_names_its_fibres(const volume::Grid& grid);

/// The metadata key of the lattice a cloth's fibres were voxelized on (record_voxelized_lattice).
inline constexpr const char* kVoxelizedLatticeKey = "voxelized_lattice";

/// Records the grid's own lattice as the generator wrote it: voxel size, origin and the index
/// box of its active voxels (metadata kVoxelizedLatticeKey, JSON). Called once, on the grid the
/// voxelizer made; nothing is recorded for an empty grid (a rank that holds no leaves).
void record_voxelized_lattice(volume::Grid& grid);

/// The lattice a cloth's fibres were voxelized on, as record_voxelized_lattice writes it.
struct VoxelizedLattice {
  double voxel_size = 0.0;
  std::array<double, 3> origin{};
  volume::IndexBox active;  ///< index box of the active voxels
};

/// The lattice the grid records (metadata kVoxelizedLatticeKey). Throws weft::Error naming `what`
/// when it records none (an earlier weft gen: its placement cannot be checked) or the record is
/// invalid: not JSON, a voxel size not finite and > 0, an origin not finite, an index that is
/// not an integer or is beyond the index range (|index| <= volume::kMaxIndex), an empty box.
[[nodiscard]] VoxelizedLattice read_voxelized_lattice(const volume::Grid& grid, const std::string& what);

/// Throws weft::Error naming `what` unless the grid is on `lattice` (docs/validate.md §Fibre
/// ground truth): its voxel size (to 1e−9 relative) and the world box of its active voxels,
/// origin + h·index, to 1e−6 voxel plus the rounding of the coordinates. A grid moved (origin or
/// index origin), resampled or cut after `weft gen` keeps its provenance; it is refused with how
/// far it moved, not compared with fibres that are no longer where its voxels are.
void check_on_lattice(const volume::Grid& grid, const VoxelizedLattice& lattice, const std::string& what);

/// check_on_lattice against the lattice the grid itself records (read_voxelized_lattice).
void check_voxelized_lattice(const volume::Grid& grid, const std::string& what);

/// The fibres the grid was voxelized from: the recorded cloth spec (seed included) run through
/// the fibre generator again. Throws weft::Error naming `what` when the grid records no cloth
/// spec (not written by `weft gen`), is not on the lattice they were voxelized on
/// (check_voxelized_lattice, checked first), the spec cannot be rebuilt (e.g. its imported yarn
/// file is gone), or the regenerated fibres' volume differs from the one recorded at generation.
[[nodiscard]] FiberSet fibers_of_grid(const volume::Grid& grid, const std::string& what,
                                      ProgressSink& progress = null_progress());

}  // namespace weft::cloth
