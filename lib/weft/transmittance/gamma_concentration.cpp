#include "weft/transmittance/gamma_concentration.h"

#include <cmath>
#include <limits>

#include "weft/core/error.h"
#include "weft/transmittance/overflow.h"
#include "weft/transmittance/shape_rate.h"

namespace weft::transmittance {

GammaConcentration::GammaConcentration(double mean_extinction, double alpha)
    : mean_extinction_(mean_extinction), alpha_(alpha), inverse_alpha_(0.0), scale_(kInfinity) {
  if (!(std::isfinite(mean_extinction) && mean_extinction >= 0.0)) {
    fail("gamma law: mean_extinction must be finite and >= 0, got {}", mean_extinction);
  }
  // NaN first: an ordered comparison with NaN raises FE_INVALID (traps in the fp-trap build).
  if (std::isnan(alpha) || !(alpha > 0.0)) {
    fail("gamma law: alpha must be > 0 (or inf for the exponential limit), got {}", alpha);
  }
  inverse_alpha_ = quotient_or_infinity(1.0, alpha);
  if (mean_extinction > 0.0) scale_ = quotient_or_infinity(alpha, mean_extinction);
}

GammaConcentration GammaConcentration::from_sigma_alpha_beta(double sigma, double alpha, double beta) {
  if (!(std::isfinite(sigma) && sigma >= 0.0)) fail("gamma law: sigma must be finite and >= 0, got {}", sigma);
  if (!(std::isfinite(alpha) && alpha > 0.0)) fail("gamma law: alpha must be finite and > 0, got {}", alpha);
  if (!(std::isfinite(beta) && beta > 0.0)) fail("gamma law: beta must be finite and > 0, got {}", beta);
  // Eq. 20: σt/β = μ̄t/α with μ̄ = σα/β.
  const double mean = product_or_infinity(sigma, quotient_or_infinity(alpha, beta));
  if (!std::isfinite(mean))
    fail("gamma law: mean extinction sigma*alpha/beta overflows ({}*{}/{})", sigma, alpha, beta);
  return {mean, alpha};
}

GammaConcentration GammaConcentration::from_concentration(double sigma, double mean_concentration,
                                                          double var_concentration) {
  if (!(std::isfinite(sigma) && sigma >= 0.0)) fail("gamma law: sigma must be finite and >= 0, got {}", sigma);
  if (!(std::isfinite(mean_concentration) && mean_concentration >= 0.0)) {
    fail("gamma law: mean_concentration must be finite and >= 0, got {}", mean_concentration);
  }
  if (!(std::isfinite(var_concentration) && var_concentration >= 0.0)) {
    fail("gamma law: var_concentration must be finite and >= 0, got {}", var_concentration);
  }
  if (mean_concentration == 0.0 && var_concentration > 0.0) {
    fail("gamma law: a concentration with mean 0 cannot have variance {} (C >= 0)", var_concentration);
  }
  // α = C̄²/Var C (Eq. 19); Var C = 0 is the exact exponential limit (S.46), not 0/0.
  const double alpha = gamma_shape_rate(mean_concentration, var_concentration).alpha;
  if (!(alpha > 0.0)) {
    fail("gamma law: alpha = mean_concentration^2/var_concentration underflows to 0 ({}^2/{})", mean_concentration,
         var_concentration);
  }
  return {product_or_infinity(sigma, mean_concentration), alpha};
}

namespace {
// log1p(x)/x by its Taylor series for small x, where μ̄t·(log1p(x)/x) keeps full relative
// accuracy even when x = μ̄t/α is subnormal (t = 1e−300, α = 1e15).
double log1p_over_x(double x) {
  if (x < 1e-4) return 1.0 - x * (0.5 - x * (1.0 / 3.0 - x * (0.25 - x * 0.2)));
  return std::log1p(x) / x;
}
}  // namespace

double GammaConcentration::optical_exponent(double t) const {
  if (mean_extinction_ == 0.0 || t == 0.0) return 0.0;
  if (t == kInfinity) return kInfinity;
  if (alpha_ == kInfinity) return product_or_infinity(mean_extinction_, t);  // S.46: the exponential limit
  const double mu_t = product_or_infinity(mean_extinction_, t);
  const double x = std::isfinite(mu_t) ? quotient_or_infinity(mu_t, alpha_)
                                       : product_or_infinity(mean_extinction_, quotient_or_infinity(t, alpha_));
  if (x < 1e-4) {
    // α·log1p(x) = μ̄t·log1p(x)/x; μ̄t = αx is finite here because x is small.
    return (std::isfinite(mu_t) ? mu_t : alpha_ * x) * log1p_over_x(x);
  }
  if (std::isfinite(x)) return product_or_infinity(alpha_, std::log1p(x));
  // μ̄t/α overflows: log1p(x) = log x to double precision.
  return product_or_infinity(alpha_, std::log(mean_extinction_) + std::log(t) - std::log(alpha_));
}

double GammaConcentration::transmittance(double t) const { return std::exp(-optical_exponent(t)); }

double GammaConcentration::log_transmittance(double t) const { return -optical_exponent(t); }

double GammaConcentration::hazard(double t) const {
  // Σ = p/T = μ̄/(1 + μ̄t/α) (Eq. 21 over Eq. 20).
  if (mean_extinction_ == 0.0) return 0.0;
  if (alpha_ == kInfinity) return mean_extinction_;
  if (t == kInfinity) return 0.0;
  const double mu_t = product_or_infinity(mean_extinction_, t);
  const double x = std::isfinite(mu_t) ? quotient_or_infinity(mu_t, alpha_)
                                       : product_or_infinity(mean_extinction_, quotient_or_infinity(t, alpha_));
  if (!std::isfinite(x)) return alpha_ / t;  // μ̄/(μ̄t/α)
  return mean_extinction_ / (1.0 + x);
}

double GammaConcentration::pdf(double t) const {
  // p = Σ·T (S.49); in log space where T underflows but Σ·T may not (huge μ̄).
  const double sigma = hazard(t);
  if (sigma == 0.0) return 0.0;
  const double log_t = log_transmittance(t);
  if (log_t > -600.0) return sigma * std::exp(log_t);
  return std::exp(std::log(sigma) + log_t);
}

double GammaConcentration::sample(Pcg32& rng) const {
  if (mean_extinction_ == 0.0) return kInfinity;
  // 1 − T(t) = ξ ⇔ (1 + μ̄t/α)^α = 1/u ⇔ t = (α/μ̄)·expm1(E/α), E = −log u ~ Exp(1).
  const double e = -std::log(1.0 - rng.uniform());
  if (alpha_ == kInfinity) return saturating_quotient(e, mean_extinction_);
  // Small α: E/α may be far beyond expm1's range (T ~ t^−α has mass past DBL_MAX); the draw
  // then saturates at DBL_MAX (law.h) without overflowing.
  const double exponent = product_or_infinity(e, inverse_alpha_);
  if (exponent > 700.0) {
    // (α/μ̄)·expm1(y) = e^{log α − log μ̄ + y} to double precision for y > 700.
    const double log_t = std::log(alpha_) - std::log(mean_extinction_) + exponent;
    constexpr double kLogMax = 709.78;  // just below log(DBL_MAX) = 709.7827…
    return log_t < kLogMax ? std::exp(log_t) : std::numeric_limits<double>::max();
  }
  if (std::isfinite(scale_)) return saturating_product(scale_, std::expm1(exponent));
  // α/μ̄ overflows (huge α, tiny μ̄): α·expm1(E/α) stays near E, so divide by μ̄ last.
  return saturating_quotient(alpha_ * std::expm1(e / alpha_), mean_extinction_);
}

double GammaConcentration::mean_free_path() const {
  if (mean_extinction_ == 0.0) return kInfinity;
  if (alpha_ == kInfinity) return quotient_or_infinity(1.0, mean_extinction_);
  if (!(alpha_ > 1.0)) return kInfinity;
  // S.54: ∫(1 + μ̄t/α)^−α dt = α/(μ̄(α − 1)).
  return quotient_or_infinity(alpha_ / (alpha_ - 1.0), mean_extinction_);
}

std::shared_ptr<const Law> GammaConcentration::closed_form_scatterer_partner() const {
  if (alpha_ == kInfinity) return std::make_shared<GammaConcentration>(*this);
  // Same scale α/μ̄, shape α + 1 ⇒ mean extinction μ̄(α + 1)/α.
  const double mean = product_or_infinity(mean_extinction_, 1.0 + inverse_alpha_);
  if (mean == kInfinity) {
    fail(
        "reciprocal pair: the scatterer partner of gamma {{mean_extinction={}, alpha={}}} has mean extinction "
        "mean_extinction*(1 + 1/alpha) beyond the largest double",
        mean_extinction_, alpha_);
  }
  return std::make_shared<GammaConcentration>(mean, alpha_ + 1.0);
}

std::shared_ptr<const Law> GammaConcentration::closed_form_source_partner() const {
  if (alpha_ == kInfinity) return std::make_shared<GammaConcentration>(*this);
  if (!(alpha_ > 1.0)) return nullptr;
  return std::make_shared<GammaConcentration>(mean_extinction_ * ((alpha_ - 1.0) / alpha_), alpha_ - 1.0);
}

void GammaConcentration::require_alpha_above_one(const char* what) const {
  if (!(alpha_ > 1.0)) {
    fail("gamma law: {} needs alpha > 1 (T is not integrable for alpha <= 1), got alpha = {}", what, alpha_);
  }
  if (mean_extinction_ == 0.0) fail("gamma law: {} needs mean_extinction > 0 (T = 1 is not integrable)", what);
}

double GammaConcentration::pdf_proportional_to_transmittance(double t) const {
  require_alpha_above_one("sampling p proportional to T");
  return transmittance(t) / mean_free_path();
}

double GammaConcentration::cdf_proportional_to_transmittance(double t) const {
  require_alpha_above_one("sampling p proportional to T");
  if (alpha_ == kInfinity) return -std::expm1(-mean_extinction_ * t);
  // 1 − (1 + μ̄t/α)^{1−α} = −expm1(−(α − 1)·log1p(μ̄t/α)).
  const double exponent = optical_exponent(t) * ((alpha_ - 1.0) / alpha_);
  return -std::expm1(-exponent);
}

double GammaConcentration::sample_proportional_to_transmittance(Pcg32& rng) const {
  require_alpha_above_one("sampling p proportional to T");
  const double e = -std::log(1.0 - rng.uniform());
  if (alpha_ == kInfinity) return saturating_quotient(e, mean_extinction_);
  // (1 + μ̄t/α)^{α−1} = 1/u ⇔ t = (α/μ̄)·expm1(E/(α − 1)), which is S.57; for α near 1 the
  // exponent leaves expm1's range and the draw saturates at DBL_MAX (law.h), as in sample().
  const double exponent = quotient_or_infinity(e, alpha_ - 1.0);
  if (exponent > 700.0) {
    const double log_t = std::log(alpha_) - std::log(mean_extinction_) + exponent;
    constexpr double kLogMax = 709.78;  // just below log(DBL_MAX) = 709.7827…
    return log_t < kLogMax ? std::exp(log_t) : std::numeric_limits<double>::max();
  }
  return saturating_quotient(alpha_ * std::expm1(exponent), mean_extinction_);
}

}  // namespace weft::transmittance
