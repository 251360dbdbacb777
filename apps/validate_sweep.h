#pragma once
/// @file
/// @brief `weft validate --sweep` (accuracy vs time), called by the validate command.

#include <chrono>
#include <string>

#include <nlohmann/json.hpp>

#include "command.h"
#include "validate_common.h"
#include "weft/fit/validation.h"
#include "weft/volume/grid.h"

namespace weft::app {

/// Runs the sweep on `grid` with the beams, σ and seed of `spec`; writes accuracy_time.csv,
/// sweep.json and (unless no_plot) accuracy_time.png into o.out; prints the table.
int run_sweep(const SweepOutputOptions& o, const Context& ctx, const volume::Grid& grid,
              const fit::ValidationSpec& spec, const std::string& title, nlohmann::json input, nlohmann::json timings,
              std::chrono::steady_clock::time_point t_start);

}  // namespace weft::app
