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

}  // namespace weft::media2d
