#include "weft/transmittance/linear.h"

#include <cmath>

#include "weft/core/error.h"

namespace weft::transmittance {

Linear::Linear(double mean_extinction) : mean_extinction_(mean_extinction) {
  if (!(std::isfinite(mean_extinction) && mean_extinction >= 0.0)) {
    fail("linear law: mean_extinction must be finite and >= 0, got {}", mean_extinction);
  }
}

double Linear::remainder(double t) const {
  if (mean_extinction_ == 0.0) return 1.0;
  if (t == kInfinity) return 0.0;
  return std::max(0.0, std::fma(-mean_extinction_, t, 1.0));
}

double Linear::transmittance(double t) const { return remainder(t); }

double Linear::log_transmittance(double t) const {
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
  return mean_extinction_ / r;  // S.60
}

double Linear::sample(Pcg32& rng) const {
  if (mean_extinction_ == 0.0) return kInfinity;
  return rng.uniform() / mean_extinction_;  // S.61, ξ ∈ [0, 1)
}

double Linear::mean_free_path() const { return mean_extinction_ == 0.0 ? kInfinity : 0.5 / mean_extinction_; }

}  // namespace weft::transmittance
