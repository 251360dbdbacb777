#include "weft/transmittance/exponential.h"

#include <cmath>

#include "weft/core/error.h"
#include "weft/transmittance/overflow.h"

namespace weft::transmittance {

Exponential::Exponential(double mu) : mu_(mu) {
  if (!(std::isfinite(mu) && mu >= 0.0)) fail("exponential law: mu must be finite and >= 0, got {}", mu);
}

// μ·t with 0·∞ taken as 0: a vacuum stays a vacuum at t = +∞.
// +∞ where μt exceeds DBL_MAX (no FE_OVERFLOW).
static double optical_depth(double mu, double t) { return product_or_infinity(mu, t); }

double Exponential::transmittance(double t) const { return std::exp(-optical_depth(mu_, t)); }

double Exponential::log_transmittance(double t) const { return -optical_depth(mu_, t); }

double Exponential::pdf(double t) const {
  if (mu_ == 0.0) return 0.0;
  return mu_ * std::exp(-optical_depth(mu_, t));
}

double Exponential::hazard(double /*t*/) const { return mu_; }

double Exponential::sample(Pcg32& rng) const {
  if (mu_ == 0.0) return kInfinity;
  // u ∈ (0, 1] so log(u) is finite; 1 − uniform() is the same distribution.
  const double u = 1.0 - rng.uniform();
  return saturating_quotient(-std::log(u), mu_);  // DBL_MAX beyond the largest double (law.h)
}

double Exponential::mean_free_path() const { return mu_ == 0.0 ? kInfinity : quotient_or_infinity(1.0, mu_); }

}  // namespace weft::transmittance
