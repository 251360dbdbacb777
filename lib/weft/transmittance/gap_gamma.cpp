#include "weft/transmittance/gap_gamma.h"

#include <cmath>

#include "weft/core/error.h"

namespace weft::transmittance {

namespace {

double checked_gap(double gap) {
  // NaN first: an ordered comparison with NaN raises FE_INVALID (traps in the fp-trap build).
  if (std::isnan(gap) || !(gap >= 0.0 && gap < 1.0)) {
    fail("gap-gamma law: gap must be in [0, 1), got {} (gap = 1 is a vacuum: use exponential with mu = 0)", gap);
  }
  return gap;
}

GammaConcentration checked_fibre(double mean_extinction, double alpha) {
  if (!(std::isfinite(mean_extinction) && mean_extinction >= 0.0)) {
    fail("gap-gamma law: mean_extinction (of the non-gap rays) must be finite and >= 0, got {}", mean_extinction);
  }
  if (std::isnan(alpha) || !(alpha > 0.0)) {
    fail("gap-gamma law: alpha must be > 0 (or inf for gap + exponential), got {}", alpha);
  }
  return {mean_extinction, alpha};
}

/// The factories' gamma parts, with the gamma law's messages re-labelled for this law.
template <typename F>
GammaConcentration relabelled(F make) {
  try {
    return make();
  } catch (const Error& e) {
    std::string message = e.what();
    if (message.rfind("gamma law:", 0) == 0) message = "gap-gamma law:" + message.substr(10);
    throw Error(message);
  }
}

}  // namespace

GapGamma::GapGamma(double gap, double mean_extinction, double alpha)
    : gap_(checked_gap(gap)),
      fibre_(checked_fibre(mean_extinction, alpha)),
      // 1 − f₀ is exact for f₀ ≥ ½ (Sterbenz), so f₀ = 1 − 1e−12 keeps its fibre share exactly.
      mixture_({{gap_, 0.0, kInfinity}, {1.0 - gap_, mean_extinction, alpha}}) {}

GapGamma GapGamma::from_sigma_alpha_beta(double gap, double sigma, double alpha, double beta) {
  const GammaConcentration fibre =
      relabelled([&] { return GammaConcentration::from_sigma_alpha_beta(sigma, alpha, beta); });
  return {gap, fibre.mean_extinction(), fibre.alpha()};
}

GapGamma GapGamma::from_concentration(double gap, double sigma, double mean_concentration, double var_concentration) {
  const GammaConcentration fibre =
      relabelled([&] { return GammaConcentration::from_concentration(sigma, mean_concentration, var_concentration); });
  return {gap, fibre.mean_extinction(), fibre.alpha()};
}

std::shared_ptr<const Law> GapGamma::closed_form_scatterer_partner() const {
  // p_Q = (1 − f₀)μ̄_c(1 + x)^−(α+1) and p_Q(0) = (1 − f₀)μ̄_c: the gap fraction cancels, and
  // T_S is the gamma law's partner. ∫T_S = 1/μ̄_c, so p_Q = (1 − f₀)·T_S/ℓ_S: the reciprocity
  // p_Q = T_S/ℓ_S holds on the rays that can collide (docs/transmittance.md).
  return fibre_.closed_form_scatterer_partner();
}

std::shared_ptr<const Law> GapGamma::closed_form_source_partner() const {
  if (gap_ > 0.0) return nullptr;
  return fibre_.closed_form_source_partner();
}

}  // namespace weft::transmittance
