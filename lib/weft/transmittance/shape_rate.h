#pragma once
/// @file
/// @brief Concentration moments → gamma shape and rate (Eq. 19), written once and overflow-safe.

namespace weft::transmittance {

/// Gamma shape α [1] and rate β [1/concentration] of a concentration C ~ Gamma(α, β).
struct ShapeRate {
  double alpha = 0.0;
  double beta = 0.0;
};

/// α = C̄²/Var C and β = C̄/Var C (Eq. 19) for C̄ ≥ 0, from β first and α = C̄·β, so that C̄²
/// never overflows while α is representable (C̄ > 1e154); a quotient or product beyond the
/// doubles is +∞. Var C ≤ 0 is exactly the exponential limit α = β = +∞ (S.46), not 0/0.
[[nodiscard]] ShapeRate gamma_shape_rate(double mean, double var);

}  // namespace weft::transmittance
