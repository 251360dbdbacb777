#pragma once
/// @file
/// @brief The best gamma law by least squares on the ground truth (a diagnostic, never a prediction).

#include "weft/fit/gamma_moments.h"
#include "weft/volume/beam.h"

namespace weft::fit {

/// Levenberg–Marquardt (Eigen) fit of (α, β) at fixed σ to T_gt(t), least squares on T,
/// started at `start` (or at a unit α with the curve's initial slope when `start` is
/// degenerate). Returns `start` unchanged for a curve that never drops below 1.
struct LeastSquaresFit {
  GammaFit fit;
  double rms = 0.0;  ///< RMS residual on T
  int iterations = 0;
  bool converged = false;
};
[[nodiscard]] LeastSquaresFit fit_gamma_to_curve(const volume::TransmittanceCurve& ground_truth, double sigma,
                                                 const GammaFit& start);

}  // namespace weft::fit
