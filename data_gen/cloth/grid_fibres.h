#pragma once
/// @file
/// @brief The fibres behind a grid: a generated cloth's fibres as geometry for exact ray
/// intersection (weft/fibres), and the fibres of a grid written by `weft gen`, regenerated from
/// the cloth spec its provenance records (docs/validate.md §Fibre ground truth).

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

/// The fibres the grid was voxelized from: the recorded cloth spec (seed included) run through
/// the fibre generator again. Throws weft::Error naming `what` when the grid records no cloth
/// spec (not written by `weft gen`), the spec cannot be rebuilt (e.g. its imported yarn file is
/// gone), or the regenerated fibres' volume differs from the one recorded at generation.
[[nodiscard]] FiberSet fibers_of_grid(const volume::Grid& grid, const std::string& what,
                                      ProgressSink& progress = null_progress());

}  // namespace weft::cloth
