#include "weft/transmittance/gamma_mixture.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/transmittance/overflow.h"

namespace weft::transmittance {

namespace {

/// a + b for a, b ≥ 0, +∞ where the sum exceeds DBL_MAX (no FE_OVERFLOW).
double sum_or_infinity(double a, double b) {
  constexpr double kMax = std::numeric_limits<double>::max();
  if (a == kInfinity || b == kInfinity || a > kMax - b) return kInfinity;
  return a + b;
}

}  // namespace

GammaMixture::GammaMixture(std::vector<GammaComponent> components) : components_(std::move(components)) {
  if (components_.empty()) fail("gamma-mixture law: no components (give at least one weight, alpha, mean_extinction)");
  double sum = 0.0;
  for (std::size_t i = 0; i < components_.size(); ++i) {
    const GammaComponent& c = components_[i];
    const std::size_t n = i + 1;
    // NaN first: an ordered comparison with NaN raises FE_INVALID (traps in the fp-trap build).
    if (!(std::isfinite(c.weight) && c.weight >= 0.0))
      fail("gamma-mixture law: weight_{} must be finite and >= 0, got {}", n, c.weight);
    if (!(std::isfinite(c.mean_extinction) && c.mean_extinction >= 0.0)) {
      fail("gamma-mixture law: mean_extinction_{} must be finite and >= 0 (0 = a gap component), got {}", n,
           c.mean_extinction);
    }
    if (std::isnan(c.alpha) || !(c.alpha > 0.0))
      fail("gamma-mixture law: alpha_{} must be > 0 (or inf for an exponential component), got {}", n, c.alpha);
    sum += c.weight;
  }
  if (!(std::fabs(sum - 1.0) <= kWeightTolerance)) {
    fail("gamma-mixture law: the weights sum to {:.12g}; they must sum to 1 (within {})", sum, kWeightTolerance);
  }
  for (auto& c : components_) c.weight /= sum;
  double cumulative = 0.0;
  for (const auto& c : components_) {
    if (!(c.weight > 0.0)) continue;
    active_.push_back({std::log(c.weight), GammaConcentration(c.mean_extinction, c.alpha)});
    weights_.push_back(c.weight);
    cumulative += c.weight;
    cumulative_.push_back(cumulative);
    max_mean_extinction_ = std::max(max_mean_extinction_, c.mean_extinction);
  }
  cumulative_.back() = 1.0;  // every u in [0, 1) picks a component despite rounding of the sum
}

std::vector<Parameter> GammaMixture::parameters() const {
  std::vector<Parameter> out;
  for (std::size_t i = 0; i < components_.size(); ++i) {
    out.push_back({fmt::format("weight_{}", i + 1), components_[i].weight});
    out.push_back({fmt::format("alpha_{}", i + 1), components_[i].alpha});
    out.push_back({fmt::format("mean_extinction_{}", i + 1), components_[i].mean_extinction});
  }
  return out;
}

double GammaMixture::transmittance(double t) const {
  if (t == 0.0) return 1.0;
  // Positive terms: no cancellation; each T_i = exp(−α_i log1p(μ̄_i t/α_i)) is the gamma law's.
  double sum = 0.0;
  for (std::size_t i = 0; i < active_.size(); ++i) sum += weights_[i] * std::exp(-active_[i].law.optical_exponent(t));
  return std::min(sum, 1.0);
}

double GammaMixture::log_transmittance(double t) const {
  if (t == 0.0) return 0.0;
  // 1 − T = Σ w_i (1 − T_i) with 1 − T_i = −expm1(−E_i) exact near t = 0 and for tiny
  // non-gap fractions (f0 = 1 − 1e−12): log T = log1p(−(1 − T)) keeps every digit of log T.
  double deficit = 0.0;
  for (std::size_t i = 0; i < active_.size(); ++i)
    deficit += weights_[i] * -std::expm1(-active_[i].law.optical_exponent(t));
  if (deficit < 0.5) return std::log1p(-deficit);
  // T ≤ ½: log-sum-exp of log w_i − E_i, streaming (one pass, no underflow of T).
  double m = -kInfinity;
  double s = 0.0;
  for (const auto& a : active_) {
    const double x = a.log_weight - a.law.optical_exponent(t);
    if (x == -kInfinity) continue;
    if (x > m) {
      s = s * std::exp(m - x) + 1.0;
      m = x;
    } else {
      s += std::exp(x - m);
    }
  }
  if (m == -kInfinity) return -kInfinity;
  return m + std::log(s);
}

double GammaMixture::hazard(double t) const {
  if (max_mean_extinction_ == 0.0) return 0.0;
  if (t == kInfinity) {
    // The groups alive at t → ∞: a gap (Σ = 0) or the heaviest gamma tail (Σ ~ α/t → 0) wins;
    // among exponential components only, the smallest extinction does.
    double smallest = kInfinity;
    for (const auto& a : active_) {
      if (a.law.mean_extinction() == 0.0 || a.law.alpha() != kInfinity) return 0.0;
      smallest = std::min(smallest, a.law.mean_extinction());
    }
    return smallest;
  }
  // Σ = Σ_i w_i T_i Σ_i / Σ_i w_i T_i, in log space (softmax of log w_i − E_i) so that it stays
  // finite where every T_i underflows; the Σ_i are scaled by max μ̄ ≥ Σ_i so no sum overflows.
  double m = -kInfinity;
  double s = 0.0;
  double num = 0.0;
  double smallest = kInfinity;
  for (const auto& a : active_) {
    const double h = a.law.hazard(t) / max_mean_extinction_;
    smallest = std::min(smallest, h);
    const double x = a.log_weight - a.law.optical_exponent(t);
    if (x == -kInfinity) continue;
    if (x > m) {
      const double rescale = std::exp(m - x);
      s = s * rescale + 1.0;
      num = num * rescale + h;
      m = x;
    } else {
      const double r = std::exp(x - m);
      s += r;
      num += r * h;
    }
  }
  // Every T_i is 0 as a double (μ̄t beyond DBL_MAX): the smallest hazard, a lower bound.
  if (m == -kInfinity) return smallest * max_mean_extinction_;
  return std::min(num / s, 1.0) * max_mean_extinction_;
}

double GammaMixture::pdf(double t) const {
  // p = Σ·T (S.49 for each component, summed); in log space where T underflows.
  const double sigma = hazard(t);
  if (sigma == 0.0) return 0.0;
  const double log_t = log_transmittance(t);
  if (log_t > -600.0) return sigma * std::exp(log_t);
  return std::exp(std::log(sigma) + log_t);
}

double GammaMixture::sample(Pcg32& rng) const {
  // Composition: P(component i) = w_i, then t ~ p_i; a gap component returns +∞ (law.h).
  const double u = rng.uniform();
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), u);
  const auto i = static_cast<std::size_t>(
      std::min<std::ptrdiff_t>(it - cumulative_.begin(), static_cast<std::ptrdiff_t>(active_.size()) - 1));
  return active_[i].law.sample(rng);
}

double GammaMixture::mean_free_path() const {
  // ℓ = ∫ Σ w_i T_i = Σ w_i ℓ_i.
  double ell = 0.0;
  for (std::size_t i = 0; i < active_.size(); ++i) {
    const double li = active_[i].law.mean_free_path();
    if (li == kInfinity) return kInfinity;
    ell = sum_or_infinity(ell, product_or_infinity(weights_[i], li));
  }
  return ell;
}

std::shared_ptr<const Law> GammaMixture::closed_form_scatterer_partner() const {
  // p_Q = Σ w_i μ̄_i (1 + μ̄_i t/α_i)^−(α_i+1) (Eq. 21 per component), p_Q(0) = Σ w_i μ̄_i, so
  // T_S = Σ ρ_i (1 + μ̄_i t/α_i)^−(α_i+1) with ρ_i = w_i μ̄_i/Σ_j w_j μ̄_j: component i's own
  // gamma partner (shape α_i + 1, mean extinction μ̄_i(α_i + 1)/α_i), weighted by where the
  // scatterers are (∝ extinction). Weights are scaled by max μ̄ so no product overflows.
  std::vector<GammaComponent> partner;
  double total = 0.0;
  for (std::size_t i = 0; i < active_.size(); ++i) {
    const double mu = active_[i].law.mean_extinction();
    const double rho = weights_[i] * (mu / max_mean_extinction_);
    if (!(rho > 0.0)) continue;
    const double alpha = active_[i].law.alpha();
    const double mean = product_or_infinity(mu, 1.0 + quotient_or_infinity(1.0, alpha));
    if (mean == kInfinity) {
      fail(
          "reciprocal pair: the scatterer partner of gamma-mixture component {} (mean_extinction={}, alpha={}) has "
          "mean extinction mean_extinction*(1 + 1/alpha) beyond the largest double",
          i + 1, mu, alpha);
    }
    partner.push_back({rho, mean, alpha + 1.0});
    total += rho;
  }
  for (auto& c : partner) c.weight /= total;
  return std::make_shared<GammaMixture>(std::move(partner));
}

std::shared_ptr<const Law> GammaMixture::closed_form_source_partner() const {
  // ∫_t^∞ T_S/ℓ_S = Σ w_i ∫_t^∞ T_i/ℓ_S = Σ (w_i ℓ_i/ℓ_S)·T_Q,i(t), T_Q,i the gamma source partner
  // of component i (shape α_i − 1, mean extinction μ̄_i(α_i − 1)/α_i); ℓ_S = Σ w_i ℓ_i.
  double max_ell = 0.0;
  for (const auto& a : active_) {
    const double li = a.law.mean_free_path();
    if (li == kInfinity) return nullptr;  // ℓ_S = ∞: the pair refuses before asking
    max_ell = std::max(max_ell, li);
  }
  if (!(max_ell > 0.0)) return nullptr;
  std::vector<GammaComponent> partner;
  double total = 0.0;
  for (std::size_t i = 0; i < active_.size(); ++i) {
    const GammaConcentration& law = active_[i].law;
    const double rho = weights_[i] * (law.mean_free_path() / max_ell);
    if (!(rho > 0.0)) continue;
    const double alpha = law.alpha();
    const double mean = alpha == kInfinity ? law.mean_extinction() : law.mean_extinction() * ((alpha - 1.0) / alpha);
    partner.push_back({rho, mean, alpha == kInfinity ? alpha : alpha - 1.0});
    total += rho;
  }
  for (auto& c : partner) c.weight /= total;
  return std::make_shared<GammaMixture>(std::move(partner));
}

}  // namespace weft::transmittance
