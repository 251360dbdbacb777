#pragma once
/// @file
/// @brief Moment matching (Eq. 19): the gamma law of concentration statistics, the model and baseline
/// laws, pooling the axes, and a model's errors against the ground truth.

#include <cmath>
#include <cstddef>
#include <vector>

#include "weft/fit/window_stats.h"
#include "weft/transmittance/law.h"
#include "weft/volume/beam.h"

namespace weft::fit {

/// The gamma concentration law from moments (Eq. 19): α = C̄²/Var C, β = C̄/Var C.
/// Var C = 0 is the exponential law (α = β = ∞); C̄ = 0 is a vacuum (T ≡ 1).
struct GammaFit {
  double sigma = 1.0;
  double mean_concentration = 0.0;
  double var_concentration = 0.0;
  double alpha = 0.0;  ///< +∞ for the exponential limit
  double beta = 0.0;   ///< +∞ for the exponential limit
  [[nodiscard]] bool exponential() const { return var_concentration == 0.0 || !std::isfinite(alpha); }
  [[nodiscard]] bool vacuum() const { return mean_concentration == 0.0; }
  [[nodiscard]] double mean_extinction() const { return sigma * mean_concentration; }
};

/// Moment matching; throws weft::Error for negative or non-finite inputs, σ ≤ 0, or a zero mean
/// with a positive variance (impossible for concentrations ≥ 0).
[[nodiscard]] GammaFit gamma_from_moments(double mean, double variance, double sigma);
/// The law of `fit` from the transmittance library: gamma, or exponential when Var C = 0
/// (including the vacuum, μ = 0).
[[nodiscard]] transmittance::LawPtr model_law(const GammaFit& fit);
/// The exponential baseline with the same mean extinction σC̄.
[[nodiscard]] transmittance::LawPtr exponential_law(const GammaFit& fit);

/// Isotropic statistics: the samples of several axes pooled with equal weight per axis
/// (direction ignored): mean of means, and mean of (variance + squared deviation of the mean).
[[nodiscard]] ConcentrationStats pool(const std::vector<ConcentrationStats>& per_axis);

/// Errors of a model against the ground truth on the curve's depth grid.
struct CurveError {
  double max_abs_t = 0.0;
  double rms_abs_t = 0.0;
  double max_abs_log_t = 0.0;  ///< over depths where T_gt > 1e−6
  double rms_abs_log_t = 0.0;
  double mean_log_bias = 0.0;   ///< mean of log T_model − log T_gt there: < 0 overestimates extinction
  double below_fraction = 0.0;  ///< fraction of depths t > 0 (there) where T_model < T_gt
  std::size_t log_points = 0;
};
[[nodiscard]] CurveError compare(const volume::TransmittanceCurve& ground_truth,
                                 const std::vector<double>& model_log_t);
/// log T of `law` on the curve's depths.
[[nodiscard]] std::vector<double> log_curve(const transmittance::Law& law, const std::vector<double>& depths);

}  // namespace weft::fit
