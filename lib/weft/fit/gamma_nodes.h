#pragma once
/// @file
/// @brief The quadrature nodes of the two-scale prediction (fit/local_models.h, docs/validate.md
/// "The prediction"): the kNodes equal-probability quantiles of the persistent factor
/// P ~ Gamma(shape α, mean 1), α = 1/v_p, one set per coarse column.
///
/// Each node is found as Boost's gamma_p_inv finds it — Halley steps on the regularised
/// incomplete gamma function, P(α, x) = p, until a step is below 2⁻²⁴ of x — but started from a
/// table instead of gamma_p_inv's own first guess. That guess (a cascade of asymptotic forms) and
/// the two Halley steps that usually follow it cost as much as the node loops of a short column
/// (the z axis of a knit: docs/benchmarks.md "Validate: cheaper predictions, third pass"). The
/// table holds gamma_p_inv's nodes at shapes on a fixed lattice of ln α (step 1/16), computed
/// only where some column needs them; a node's guess is the six-point Lagrange interpolation of
/// ln(x/α) between them, close enough (about 10⁻⁹) that one Halley step, one incomplete gamma
/// function, lands within rounding of the root. A node depends on α alone, not on the other
/// columns, the thread count or the order of evaluation; it differs from gamma_p_inv's by the
/// rounding of the last step (tests `GammaNodes.*` bound the difference).

#include <cstdint>
#include <vector>

namespace weft::fit::detail {

/// Nodes per coarse column: P at probabilities (j + ½)/kNodes, j = 0 … kNodes − 1.
inline constexpr int kNodes = 32;

/// P⁻¹(α, (j + ½)/kNodes)/α in double precision (transmittance::gamma_p_inverse: Boost's
/// gamma_p_inv up to α = 10⁸, the Cornish–Fisher expansion above); the reference, and every shape
/// outside the table's range, α < 1/8 or α > 10⁸.
[[nodiscard]] double exact_gamma_node(double shape, int j);

class GammaNodes {
 public:
  /// The table for these shapes (the others — zero, negative, not finite, or outside the
  /// range — are left to exact_gamma_node).
  explicit GammaNodes(const std::vector<double>& shapes);
  /// The kNodes nodes of `shape` (any α > 0), in increasing order, into out[0 … kNodes).
  void nodes(double shape, double* out) const;

 private:
  std::vector<std::int64_t> lattice_;  ///< lattice points held (ln α = point/16), increasing
  std::vector<double> log_node_;       ///< [entry·kNodes + j]: ln(x_j/α) at the entry's α
};

}  // namespace weft::fit::detail
