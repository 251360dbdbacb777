#pragma once
/// @file
/// @brief Least-squares fits of the transmittance library's laws to measured curves.
///
/// Laws come from the registry (weft/transmittance/registry.h), so a fit evaluates exactly the
/// T(t) the renderer would use. Parameters are fitted in log space (they are all positive) by
/// Eigen's Levenberg–Marquardt, residuals (T_law(t_k) − T_k)/σ_k; 1σ errors come from
/// (JᵀJ)⁻¹, scaled by √(χ²/dof) when that exceeds 1. Neighbouring points of a transmittance
/// curve are correlated (each is a cumulative count), so χ² is a guide, not a p-value.

#include <string>
#include <vector>

#include "data_gen/media2d/simulation.h"

namespace weft::media2d {

/// @brief Fits `law` ("exponential", "gamma", "linear", "gamma-path") to T at `t` (t in the
/// curve's length unit). σ_k below `sigma_floor` are raised to it (e.g. 1/samples, so an
/// all-zero tail still weighs). Never throws for a poor fit: `converged` and `note` say so.
[[nodiscard]] LawFit fit_law(const std::string& law, const std::vector<double>& t, const std::vector<double>& T,
                             const std::vector<double>& sigma, double sigma_floor);

/// @brief The same fit to a free-path histogram: `density` holds the K bin densities
/// (T(t_k) − T(t_{k+1}))/(t_{k+1} − t_k) over the K+1 `edges` (p_Q, p_S of the simulation), and
/// the law is compared bin by bin through its own T, so the binning is exact. Unlike the points
/// of a cumulative curve, histogram bins are nearly independent (multinomial counts), so χ² and
/// its differences mean what they say: this is the fit law selection uses.
[[nodiscard]] LawFit fit_law_binned(const std::string& law, const std::vector<double>& edges,
                                    const std::vector<double>& density, const std::vector<double>& sigma,
                                    double sigma_floor);

/// @brief Bayesian information criterion of a fit: BIC = χ² + p·ln n (Schwarz 1978), with χ² as
/// −2 ln L up to a constant (Gaussian errors σ_k), p the law's parameters, n = dof + p points.
[[nodiscard]] double bic(const LawFit& fit);

/// @brief Which law describes a curve, with parsimony.
///
/// The law of lowest BIC is selected: a richer law (gamma, gamma-path: 2 parameters) wins over
/// a simpler one (exponential, linear: 1) only if it lowers χ² by more than ln n per extra
/// parameter (4.4 for 80 bins, 5.3 for 200). BIC rather than a likelihood-ratio test because
/// linear vs gamma is not nested. Select among fit_law_binned fits (histogram bins, nearly
/// independent): on a cumulative curve's correlated points Δχ² overstates the evidence for a
/// richer law many times over. Fits that did not converge are skipped unless none converged.
struct LawSelection {
  std::string curve;
  std::string selected;              ///< lowest BIC
  std::string lowest_chi2;           ///< lowest χ² whatever its parameter count
  double delta_chi2 = 0.0;           ///< χ²(selected) − χ²(lowest_chi2) ≥ 0
  double delta_bic = 0.0;            ///< BIC(lowest_chi2) − BIC(selected) ≥ 0
  std::string runner_up;             ///< second-lowest BIC
  double runner_up_delta_bic = 0.0;  ///< BIC(runner_up) − BIC(selected) ≥ 0
  static constexpr const char* kCriterion = "BIC = chi2 + p ln n (lowest wins)";
};

/// @brief Selects among the fits of `curve` (LawFit::curve); throws weft::Error if there are none.
[[nodiscard]] LawSelection select_law(const std::vector<LawFit>& fits, const std::string& curve);

}  // namespace weft::media2d
