#include "weft/render/phase.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "weft/core/error.h"
#include "weft/render/frame.h"

namespace weft::render {

void check_phase_g(double g, std::string_view where) {
  if (!(std::abs(g) <= kMaxAbsG))
    fail(
        "{}: 'g' must be in [-{:.7g}, {:.7g}] (within 1e-6 of ±1 the Henyey-Greenstein lobe is narrower than "
        "double-precision directions resolve), got {}",
        where, kMaxAbsG, kMaxAbsG, g);
}

double hg(double g, double cos_theta) {
  // 1 + g² − 2g c = (1 − g)² + 2g(1 − c) = (1 + g)² − 2g(1 + c): the form whose terms do not cancel
  // at the lobe's peak (c → 1 for g > 0, c → −1 for g < 0).
  const double d = g >= 0.0 ? (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - cos_theta)
                            : (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + cos_theta);
  return (1.0 - g) * (1.0 + g) / (4.0 * std::numbers::pi * d * std::sqrt(d));
}

Vec3 sample_hg(double g, const Vec3& dir, Pcg32& rng) {
  const double u = rng.uniform();
  // Inverting the HG CDF, cos θ = (1 + g² − q²)/(2g) with q = (1 − g²)/t, t = 1 − g + 2gu. Written
  // as 1 − cos θ = 2(1 − g)²(1 − u)(1 + gu)/t² and 1 + cos θ = 2u(1 + g)²(1 − g + gu)/t² (the
  // difference and sum of squares factored), neither cancels, and sin θ = √((1 − c)(1 + c)).
  // g → 0 gives 2(1 − u) and 2u: the isotropic draw.
  const double t = 1.0 - g + 2.0 * g * u;
  const double below = 2.0 * (1.0 - g) * (1.0 - g) * (1.0 - u) * (1.0 + g * u) / (t * t);  // 1 − cos θ
  const double above = 2.0 * u * (1.0 + g) * (1.0 + g) * (1.0 - g + g * u) / (t * t);      // 1 + cos θ
  const double cos_theta = std::clamp(below <= above ? 1.0 - below : above - 1.0, -1.0, 1.0);
  const double sin_theta = std::sqrt(std::max(0.0, below * above));
  const double phi = 2.0 * std::numbers::pi * rng.uniform();
  return from_frame(dir, sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta).normalized();
}

}  // namespace weft::render
