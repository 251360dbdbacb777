#pragma once
/// @file
/// @brief Products and quotients that overflow to +∞ (or saturate at DBL_MAX) without raising
/// FE_OVERFLOW.
///
/// The laws evaluate μt, t/θ, k/λ, … for every representable t and parameter. Where the exact
/// value exceeds DBL_MAX the answer is known (+∞ for a depth, a density or a mean free path;
/// DBL_MAX for a sampled distance, law.h), so it is returned directly instead of letting the
/// multiplication overflow: the laws then run clean with overflow trapped (preset `fp-trap`).

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft::transmittance {

namespace overflow_detail {
inline constexpr double kMax = std::numeric_limits<double>::max();
/// Results within this relative margin below DBL_MAX count as overflowing, so neither the test
/// nor the rounded result can exceed DBL_MAX.
inline constexpr double kSafe = 1.0 - 1e-15;
/// Operands below this bound can neither overflow a product nor (divisor above its inverse) a
/// quotient: the common case takes two quiet comparisons and no division (these sit on the
/// samplers' hot paths).
inline constexpr double kSmall = 1e150;
}  // namespace overflow_detail

/// a·b for a, b ≥ 0 (0 if either is 0), or +∞ where it exceeds DBL_MAX; +∞·b = +∞ for b > 0.
/// (The comparisons are the quiet std::isgreater family, so a NaN argument gives NaN without
/// raising FE_INVALID.)
[[nodiscard]] inline double product_or_infinity(double a, double b) {
  using namespace overflow_detail;
  if (std::isless(a, kSmall) && std::isless(b, kSmall)) return a * b;
  if (a == 0.0 || b == 0.0) return 0.0;
  if (std::isgreater(a, 1.0) && std::isgreater(b, 1.0) && std::isgreaterequal(a, (kMax / b) * kSafe)) {
    return std::numeric_limits<double>::infinity();
  }
  return a * b;
}

/// a/b for a ≥ 0 and b > 0, or +∞ where it exceeds DBL_MAX.
[[nodiscard]] inline double quotient_or_infinity(double a, double b) {
  using namespace overflow_detail;
  if (std::isless(a, kSmall) && std::isgreater(b, 1.0 / kSmall)) return a / b;
  if (a == 0.0) return 0.0;
  if (std::isless(b, 1.0) && std::isgreaterequal(a, (kMax * b) * kSafe)) return std::numeric_limits<double>::infinity();
  return a / b;
}

/// The same, saturating at DBL_MAX: for sampled distances (Law::sample).
[[nodiscard]] inline double saturating_product(double a, double b) {
  return std::min(product_or_infinity(a, b), overflow_detail::kMax);
}
[[nodiscard]] inline double saturating_quotient(double a, double b) {
  return std::min(quotient_or_infinity(a, b), overflow_detail::kMax);
}

}  // namespace weft::transmittance
