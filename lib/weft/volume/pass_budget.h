#pragma once
/// @file
/// @brief The one rule for the size of a pass over a grid (docs/robustness.md "Work and memory
/// budgets"): a beam (measure_beam) or a pass over a grid's voxel columns (ColumnReader: axis
/// beams, window statistics, local fields) estimates from the active box and the request the
/// bytes it would hold at once and the elementary steps it would take, and refuses before
/// allocating anything when either is over its limit. `weft measure`, `validate`, `fit` and the
/// Python module meet the same rule because it lives in the passes themselves.

#include <string_view>

#include "weft/volume/grid.h"

namespace weft::volume {

/// The largest pass, in elementary steps (a voxel read, a ray's cell crossing or one depth of
/// its profile): about an hour of one core (docs/robustness.md gives the measured rate).
inline constexpr double kMaxPassSteps = 1e12;

/// What a pass would spend: estimates in double (they may exceed any integer).
struct PassCost {
  double steps = 0.0;  ///< elementary steps, an upper bound
  double bytes = 0.0;  ///< bytes held at once, an upper bound
};

/// Throws weft::Error, "<what> over grid '<name>' would take <size>, over ...", when the cost's
/// bytes exceed default_memory_budget() (half the RAM or of ulimit -v) or its steps kMaxPassSteps.
void check_pass_cost(std::string_view what, const Grid& grid, const PassCost& cost);
/// The same for a pass over something else (`subject`, e.g. "the fibres": the exact fibre beam).
void check_pass_cost(std::string_view what, std::string_view subject, const PassCost& cost);

}  // namespace weft::volume
