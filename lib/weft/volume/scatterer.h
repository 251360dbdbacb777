#pragma once
/// @file
/// @brief Particle-origin (T_S) and source-origin (T_Q) transmittance measured in a voxel grid,
/// and the reciprocal prediction of p_Q from T_S (docs/architecture.md §6).

#include <array>
#include <cstdint>
#include <vector>

#include "weft/core/progress.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// Particle-origin (scatterer) vs source-origin transmittance in the same grid (docs/architecture.md §6):
/// S rays start at points drawn ∝ value inside the box, Q rays at points drawn uniformly in
/// the box; both in uniformly random directions (or `direction` when set). Reciprocity predicts
/// p_Q(t) = T_S(t)/ℓ_S = μ̄·T_S(t) with μ̄ the mean extinction at Q origins (= p_Q(0)).
/// The fewest rays of each kind a request may give: the standard errors need two.
inline constexpr std::uint64_t kMinScattererRays = 2;

struct ScattererSpec {
  double scale = 1.0;
  std::uint64_t rays = 100000;  ///< of each kind, >= kMinScattererRays
  std::uint64_t seed = 1;
  bool fixed_direction = false;
  std::array<double, 3> direction{0.0, 0.0, 1.0};
  double depth_step = 0.0;  ///< 0: one voxel
  double max_depth = 0.0;   ///< 0: the box diagonal
};
struct ScattererCurves {
  TransmittanceCurve t_s;        ///< rays from particles
  TransmittanceCurve t_q;        ///< rays from uniform points
  std::vector<double> p_q;       ///< −dT_Q/dt (central differences)
  std::vector<double> mu_t_s;    ///< μ̄·T_S(t), the reciprocal prediction of p_Q
  double mean_extinction = 0.0;  ///< μ̄ over the box
};
/// The checks measure_scatterer makes before any work: the spec, then its work and memory
/// against the budget of every pass (volume/pass_budget.h; docs/robustness.md "Work and memory
/// budgets"). A front end calls it to refuse a request before its other passes run.
void check_scatterer(const Grid& grid, const ScattererSpec& spec);
[[nodiscard]] ScattererCurves measure_scatterer(const Grid& grid, const ScattererSpec& spec,
                                                ProgressSink& progress = null_progress());

}  // namespace weft::volume
