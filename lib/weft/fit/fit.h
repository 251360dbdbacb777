#pragma once
/// @file
/// @brief Concentration statistics of a grid and the gamma-concentration model they predict
/// (Jarabo et al. 2018, Eq. 19–20; docs/architecture.md §6 "Predictions").
///
/// What a "window" is. A beam along axis a sees, ray by ray, the concentration averaged over the
/// depth it has crossed; the gamma model replaces that per-ray mean C_ray by a Gamma(α, β)
/// variable, so T(t) = E[exp(−σ C_ray t)] = (1 + σt/β)^−α (the Laplace transform of Eq. 19).
/// A window of length L is a segment of L along a column; its sample is the mean of C over it.
/// All window positions along every column of the face are samples (stride one voxel), so the
/// statistics describe the medium at scale L, not one curve: the model is predicted from the
/// voxels, never fitted to T_gt (that is what the separate Levenberg–Marquardt fit does, to show
/// the best any gamma law can do). Taking L = t for each depth t would reproduce T_gt by
/// construction and predict nothing. The default L is the grid's extent along the beam (the
/// depth the beam crosses); L larger than the extent is clamped to it (reported as used).

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/transmittance/law.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"

namespace weft::fit {

/// Mean and variance of window-mean concentration.
struct ConcentrationStats {
  double mean = 0.0;
  double variance = 0.0;  ///< population variance over the samples
  std::uint64_t samples = 0;
  int window_voxels = 0;  ///< window length used, in voxels
  double window = 0.0;    ///< window length used, world units
};

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

/// Moment matching; throws weft::Error for negative or non-finite inputs or σ ≤ 0.
[[nodiscard]] GammaFit gamma_from_moments(double mean, double variance, double sigma);
/// The law of `fit` from the transmittance library: gamma, or exponential when Var C = 0
/// (including the vacuum, μ = 0).
[[nodiscard]] transmittance::LawPtr model_law(const GammaFit& fit);
/// The exponential baseline with the same mean extinction σC̄.
[[nodiscard]] transmittance::LawPtr exponential_law(const GammaFit& fit);

/// The window (or block) of length `window` in voxels of edge h along an extent of n voxels:
/// round(window / h) clamped to 1..n; a window ≤ 0 is the whole extent. The one conversion every
/// statistic and model uses, so they agree on L.
[[nodiscard]] int window_voxels(double window, double h, int n);

/// Window statistics along `axis` (0, 1, 2; direction sense does not matter) for window length
/// `window` (world units; 0 = the grid's extent along the axis). Values are concentrations (or
/// extinctions, then use σ = 1). Throws weft::Error for an empty grid or a negative window.
[[nodiscard]] ConcentrationStats window_stats(const volume::Grid& grid, int axis, double window = 0.0,
                                              ProgressSink& progress = null_progress());

/// Correlation length of C along `axis`: the lag at which the autocorrelation of C along the
/// columns of the active box (about the box mean) first falls to 1/e, linearly interpolated, in
/// world units. The scale over which a ray sees one concentration: the natural window of
/// Eq. 19–20 ("local" statistics), measured from the voxels alone. Lags are searched up to
/// min(extent − 1, 128) voxels; if the autocorrelation stays above 1/e (or C is uniform) the
/// result is the extent itself.
[[nodiscard]] double correlation_length(const volume::Grid& grid, int axis, ProgressSink& progress = null_progress());

/// Isotropic statistics: the samples of several axes pooled with equal weight per axis
/// (direction ignored): mean of means, and mean of (variance + squared deviation of the mean).
[[nodiscard]] ConcentrationStats pool(const std::vector<ConcentrationStats>& per_axis);

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

/// Local statistic fields: per block of B³ voxels (aligned to multiples of B in index space),
/// the block mean C̄ and, per axis, the variance of the B² column means across the block and
/// the (α, β) they give. Blocks without any concentration are left inactive. α = β = +∞ mark
/// blocks with zero variance (exponential).
struct LocalFields {
  int block = 8;
  volume::Grid mean;                     ///< "mean_concentration"
  std::array<volume::Grid, 3> variance;  ///< "var_concentration_{x,y,z}"
  std::array<volume::Grid, 3> alpha;     ///< "alpha_{x,y,z}"
  std::array<volume::Grid, 3> beta;      ///< "beta_{x,y,z}"
  std::uint64_t blocks = 0;
};
[[nodiscard]] LocalFields local_fields(const volume::Grid& grid, int block, ProgressSink& progress = null_progress());
/// Writes every grid of `fields` into one .vdb file, atomically.
void save_local_fields(const LocalFields& fields, const std::filesystem::path& path);

}  // namespace weft::fit
