#include "weft/transmittance/linear.h"

#include <cmath>
#include <limits>

#include "weft/core/error.h"
#include "weft/transmittance/overflow.h"

namespace weft::transmittance {

Linear::Linear(double mean_extinction) : mean_extinction_(mean_extinction) {
  if (!(std::isfinite(mean_extinction) && mean_extinction >= 0.0)) {
    fail("linear law: mean_extinction must be finite and >= 0, got {}", mean_extinction);
  }
}

double Linear::remainder(double t) const {
  if (mean_extinction_ == 0.0) return 1.0;
  if (t == kInfinity || product_or_infinity(mean_extinction_, t) >= 2.0) return 0.0;  // fma would overflow
  return std::max(0.0, std::fma(-mean_extinction_, t, 1.0));
}

double Linear::transmittance(double t) const { return remainder(t); }

double Linear::log_transmittance(double t) const {
  if (mean_extinction_ == 0.0) return 0.0;  // μ̄t would be 0·∞ = NaN at t = ∞
  const double r = remainder(t);
  if (r == 0.0) return -kInfinity;
  // log1p(−μ̄t) loses the remainder's accuracy near 1/μ̄; log(r) keeps it, and for small μ̄t
  // the fma remainder is exact enough that log1p(r − 1) is as good as log1p(−μ̄t).
  if (r > 0.5) return std::log1p(-mean_extinction_ * t);
  return std::log(r);
}

double Linear::pdf(double t) const { return remainder(t) > 0.0 ? mean_extinction_ : 0.0; }

double Linear::hazard(double t) const {
  const double r = remainder(t);
  if (r == 0.0) return kInfinity;
  return saturating_quotient(mean_extinction_, r);  // S.60; DBL_MAX where μ̄/r overflows (law.h)
}

double Linear::sample(Pcg32& rng) const {
  if (mean_extinction_ == 0.0) return kInfinity;
  return saturating_quotient(rng.uniform(), mean_extinction_);  // S.61, ξ ∈ [0, 1)
}

double Linear::mean_free_path() const {
  return mean_extinction_ == 0.0 ? kInfinity : quotient_or_infinity(0.5, mean_extinction_);
}

std::shared_ptr<const Law> Linear::closed_form_scatterer_partner() const {
  return std::make_shared<LinearScatterer>(mean_extinction_);
}

LinearScatterer::LinearScatterer(double mean_extinction) : mean_extinction_(mean_extinction), end_(kInfinity) {
  if (!(std::isfinite(mean_extinction) && mean_extinction >= 0.0)) {
    fail("linear scatterer law: mean_extinction must be finite and >= 0, got {}", mean_extinction);
  }
  if (mean_extinction == 0.0) return;
  // The first double where Linear's remainder max(0, fma(−μ̄, t, 1)) is 0, so that the step
  // sits exactly where p_Q drops to 0: start at the rounded 1/μ̄ and move by single ulps.
  const Linear source(mean_extinction);
  double t = saturating_quotient(1.0, mean_extinction);
  for (int i = 0; i < 64 && source.pdf(t) > 0.0; ++i) t = std::nextafter(t, kInfinity);
  for (int i = 0; i < 64 && t > 0.0; ++i) {
    const double below = std::nextafter(t, 0.0);
    if (source.pdf(below) > 0.0) break;
    t = below;
  }
  end_ = t;
}

std::shared_ptr<const Law> LinearScatterer::closed_form_source_partner() const {
  return std::make_shared<Linear>(mean_extinction_);
}

}  // namespace weft::transmittance
