#pragma once
/// @file
/// @brief Predictive transmittance models of an axis beam from the medium's voxels alone
/// (docs/validate.md). Every function here receives the grid, the beam direction, σ, the statistics
/// scale and the depths at which to evaluate — never a measured curve: predictions cannot see
/// the ground truth.
///
/// All models use one length scale L (fit/scale.h: the yarn diameter by default). Blocks and
/// cells are anchored to the cloth (across the beam at the active box's lower corner, along it
/// at the entry face), never to the index lattice: the same voxels at another index origin give
/// the same predictions (docs/validate.md "Blocks anchored to the cloth").
///   gamma              the paper's law (Eq. 19–20): C̄, Var of the means of every window of
///                      length L along every column → (1 + σt/β)^−α. The reference row.
///   empirical          Eq. 16 with the empirical distribution of those window means (no gamma
///                      assumption): T(t) = mean over windows of exp(−σ C_w t). Its error is the
///                      error of the locality assumption ("C constant along the whole ray");
///                      gamma's excess over it is the error of the gamma shape.
///   gap-gamma          a fraction f₀ of windows holds no fibre at all (gaps, open holes), the
///                      rest a gamma law: T = f₀ + (1 − f₀)(1 + σt/β₊)^−α₊.
///   across-beam        the beam's rays grouped by where they cross the face (transverse cells of
///                      side L): a gamma law per group, T the ray-weighted mean.
///   local-exponential  the grid averaged over blocks of L³ (what a coarse render grid without
///                      statistics carries), exponential per block along each ray.
///   local-gamma        blocks of L³ carrying C̄ and the variance of their column means along
///                      the beam (fit::local_fields, the fields `weft render` reads), the gamma
///                      hazard Σ = σC̄/(1 + κ s), κ = σ Var/C̄, with the memory s measured from
///                      where the ray entered the medium (docs/render.md §5b), integrated exactly
///                      block by block; T the mean over rays.
///   local-gamma-renewal the same blocks, memory restarting at every block boundary (block means
///                      along a ray taken as independent).
///   local-gamma-two-scale the same blocks; a ray's concentration is the block mean times a
///                      persistent gamma factor (memory from the entry; its variance the measured
///                      covariance of adjacent blocks' column means) times an independent gamma
///                      factor per block (the renewal): both regimes in one model. THE prediction.

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "weft/core/progress.h"
#include "weft/fit/model_selection.h"
#include "weft/fit/window_stats.h"
#include "weft/transmittance/law.h"
#include "weft/volume/grid.h"

namespace weft::fit {

/// The prediction: one model, fixed before anything is measured, that holds both regimes of the
/// hazard's memory (long correlation along the beam: memory from the entry; short: renewal) by
/// splitting the variance of each block's column means into the part adjacent blocks share
/// (persistent) and the rest (docs/validate.md "The prediction"). No choice is made per grid.
inline constexpr const char* kPredictedModel = "local-gamma-two-scale";
inline constexpr const char* kPredictionRule =
    "one model fixed before measuring: local gamma fields of blocks of side L, a persistent gamma factor per ray "
    "(variance: the covariance of adjacent blocks' column means) times an independent one per block";

/// One model's prediction on the requested depths.
struct PredictedModel {
  std::string name;
  std::string description;
  bool uses_ground_truth = false;  ///< only least-squares references set this
  std::vector<std::pair<std::string, double>> parameters;
  std::vector<double> log_t;
  /// The one homogeneous law in distance this model predicts (gamma, gap-gamma, the
  /// across-beam gamma-mixture): what a homogeneous slab of the cloth renders with. Null for
  /// models that are not one law (empirical, the local-* fields).
  transmittance::LawPtr law;
};

struct PredictionSpec {
  std::array<double, 3> direction{1, 0, 0};  ///< an axis direction (either sense)
  double sigma = 1.0;                        ///< μ = σ·value
  double scale = 0.0;                        ///< L in world units; 0 = the extent along the beam
  /// The models to compute (isotropic and least-squares are validate's, not predict_axis's); the
  /// pass gathers only the statistics they need.
  ModelSelection models = ModelSelection::all();
};

/// What predict_axis spent, per stage: the one pass over the columns (the statistics) and the
/// curves built from it (the models). CPU seconds are the process's (every thread) over the
/// stage, so the cost compares with the ground-truth beam's (docs/benchmarks.md "Validate:
/// predictions against the truth").
struct PredictionCost {
  double statistics_seconds = 0.0;
  double statistics_cpu_seconds = 0.0;
  double models_seconds = 0.0;
  double models_cpu_seconds = 0.0;
};

/// The predictive models above that `spec.models` names, in that order, on `depths` (distances
/// from the entry face). Throws weft::Error for an empty grid, a non-axis direction or σ ≤ 0.
/// When `moments_out` is given it receives the window length L, and, when the selection needs the
/// windows, the moments of the windows of length L the models were built from (what
/// fit::window_stats(grid, axis, L) computes, equal up to rounding: window sums here come from
/// prefix sums), from the same pass, so validate reads the voxels once per beam for both
/// (`samples` stays 0 without them); `cost` receives the time of each stage. A model's curve does
/// not depend on which others are computed.
[[nodiscard]] std::vector<PredictedModel> predict_axis(const volume::Grid& grid, const PredictionSpec& spec,
                                                       const std::vector<double>& depths,
                                                       ProgressSink& progress = null_progress(),
                                                       ConcentrationStats* moments_out = nullptr,
                                                       PredictionCost* cost = nullptr);

/// The moments of the windows of length `scale` along `axis` (0, 1, 2) from predict_axis's own
/// sparse pass, the windows alone: the same bits as predict_axis's `moments_out` for a beam
/// along that axis, whatever else a run computes (what validate reports for an axis without a
/// beam and pools for the isotropic model). window_stats computes the same moments densely, equal
/// up to rounding.
[[nodiscard]] ConcentrationStats window_moments(const volume::Grid& grid, int axis, double scale,
                                                ProgressSink& progress = null_progress());

/// log T of the gamma law with window moments (mean, var) at σ: −α log1p(σ t/β), exactly the
/// exponential when var = 0 and 0 when mean = 0.
[[nodiscard]] double gamma_log_t(double sigma, double mean, double var, double t);

}  // namespace weft::fit
