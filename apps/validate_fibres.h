#pragma once
/// @file
/// @brief `weft validate --fibres`: the fibre ground truth of each validated axis on the voxel
/// beam's rays, and the voxelization error T_gt − T_fibre (docs/validate.md §Fibre ground truth).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "weft/core/progress.h"
#include "weft/fit/validation.h"
#include "weft/volume/grid.h"

namespace weft::app {

struct FibreCheck {
  nlohmann::json report;                           ///< per axis: T_fibre, the voxel − fibre error
  std::vector<volume::TransmittanceCurve> curves;  ///< per axis of the validation, T_fibre(t)
  std::vector<std::string> summary;                ///< lines for the terminal
};

/// Regenerates the fibres `grid` was made from (refused with one line when it does not name
/// them: `what` names the grid) and measures every axis of `v` through them (opaque fibres, the
/// same lattice and seed).
[[nodiscard]] FibreCheck check_against_fibres(const volume::Grid& grid, const fit::Validation& v, std::uint64_t seed,
                                              const std::string& what, ProgressSink& progress);

}  // namespace weft::app
