#include "weft/transmittance/gamma_path.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <boost/math/special_functions/erf.hpp>
#include <boost/math/special_functions/gamma.hpp>
#include <boost/random/normal_distribution.hpp>

#include "weft/core/error.h"
#include "weft/core/fp_hold.h"
#include "weft/transmittance/exponential.h"

namespace weft::transmittance {

namespace {
namespace bmp = boost::math::policies;
// Underflow to 0 is the right answer for a probability far in the tail; overflow means +∞.
using Policy = bmp::policy<bmp::underflow_error<bmp::ignore_error>, bmp::overflow_error<bmp::ignore_error>,
                           bmp::denorm_error<bmp::ignore_error>, bmp::promote_double<false>>;
const Policy kPolicy{};
// Below this Q we switch to the continued fraction in log space.
constexpr double kTinyQ = 1e-280;

}  // namespace

// The Boost.Math incomplete gamma family, with FP exceptions held (fp_hold.h): Boost evaluates
// the prefix x^k e^{−x}/Γ(k) through intermediate quantities (Γ(k), x^k, e^{−x}) that overflow,
// underflow or divide by zero for large k or extreme x, then recovers (Lanczos-scaled prefix,
// log-space fallback, or the policy above: underflow → 0, overflow → +∞). The exceptions raised
// inside are part of that algorithm, not a weft error; each result is checked by the callers
// (CF fallback where Q underflows, saturation where a scale overflows).
double regularized_gamma_q(double k, double x) {
  const HeldFpExceptions hold;
  return boost::math::gamma_q(k, x, kPolicy);
}
double regularized_gamma_p(double k, double x) {
  const HeldFpExceptions hold;
  return boost::math::gamma_p(k, x, kPolicy);
}
double gamma_density(double k, double x) {
  const HeldFpExceptions hold;
  return boost::math::gamma_p_derivative(k, x, kPolicy);
}
double gamma_quantile_cornish_fisher(double k, double z) {
  // Cornish–Fisher for Gamma(k, 1/k): cumulants κ₂ = 1/k, κ₃ = 2/k², κ₄ = 6/k³ (skewness 2/√k,
  // excess kurtosis 6/k), the expansion carried to the k⁻² term.
  const double s = 1.0 / std::sqrt(k);
  const double z2 = z * z;
  return 1.0 + s * (z + s * ((z2 - 1.0) / 3.0 +
                             s * ((z2 * z - 7.0 * z) / 36.0 - s * (3.0 * z2 * z2 + 7.0 * z2 - 16.0) / 810.0)));
}

namespace {
// z with Φ(z) = p in the lower tail (p < ½ gives z < 0), at full relative accuracy in p.
double normal_lower_quantile(double p) { return -std::sqrt(2.0) * boost::math::erfc_inv(2.0 * p, kPolicy); }
}  // namespace

// Boost's inverses iterate on the incomplete gamma functions above, so they too run with FP
// exceptions held.
double gamma_p_inverse(double k, double p) {
  if (k > kLargeGammaShape) return k * gamma_quantile_cornish_fisher(k, normal_lower_quantile(p));
  const HeldFpExceptions hold;
  return boost::math::gamma_p_inv(k, p, kPolicy);
}
double gamma_q_inverse(double k, double q) {
  if (k > kLargeGammaShape) return k * gamma_quantile_cornish_fisher(k, -normal_lower_quantile(q));
  const HeldFpExceptions hold;
  return boost::math::gamma_q_inv(k, q, kPolicy);
}

namespace {
double log_gamma(double k) {
  const HeldFpExceptions hold;
  return boost::math::lgamma(k, kPolicy);
}

}  // namespace

std::string to_string(GammaSampler sampler) {
  return sampler == GammaSampler::marsaglia_tsang ? "marsaglia-tsang" : "inversion";
}

GammaSampler parse_gamma_sampler(const std::string& text) {
  if (text == "marsaglia-tsang" || text.empty()) return GammaSampler::marsaglia_tsang;
  if (text == "inversion") return GammaSampler::inversion;
  fail("gamma-path law: unknown sampler '{}' (known: marsaglia-tsang, inversion)", text);
}

namespace {
// Boost's incomplete gamma functions give up (series iteration limit) for k beyond about 2·10¹⁰,
// where the path length is kθ to within 10⁻⁵ relative: refuse such a k at construction rather
// than fail mid-render.
constexpr double kMaxShape = 1e10;
void check_shape(double k) {
  if (!(std::isfinite(k) && k > 0.0)) fail("gamma-path law: k must be finite and > 0, got {}", k);
  if (k > kMaxShape)
    fail(
        "gamma-path law: k must be at most {:g} (the incomplete gamma function does not converge beyond "
        "about 2e10; the path length is k*theta within 1e-5 there), got {:g}",
        kMaxShape, k);
}
}  // namespace

GammaPath::GammaPath(double k, double theta, GammaSampler sampler)
    : k_(k), theta_(theta), rate_(0.0), sampler_(sampler) {
  check_shape(k);
  if (!(std::isfinite(theta) && theta > 0.0)) fail("gamma-path law: theta must be finite and > 0, got {}", theta);
  rate_ = quotient_or_infinity(1.0, theta);
}

GammaPath::GammaPath(double k, double rate, GammaSampler sampler, RateTag)
    : k_(k), theta_(0.0), rate_(rate), from_rate_(true), sampler_(sampler) {
  check_shape(k);
  if (!(std::isfinite(rate) && rate > 0.0)) fail("gamma-path law: rate must be finite and > 0, got {}", rate);
  theta_ = quotient_or_infinity(1.0, rate);  // for parameters(); may be subnormal, never used to scale
}

GammaPath GammaPath::from_rate(double k, double rate, GammaSampler sampler) { return {k, rate, sampler, RateTag{}}; }

double GammaPath::t_over_theta(double t) const {
  return from_rate_ ? product_or_infinity(t, rate_) : quotient_or_infinity(t, theta_);
}

double GammaPath::per_length(double v) const {
  return from_rate_ ? product_or_infinity(v, rate_) : quotient_or_infinity(v, theta_);
}

double GammaPath::length(double x) const {
  return from_rate_ ? saturating_quotient(x, rate_) : saturating_product(x, theta_);
}

double GammaPath::mean_free_path() const {
  return from_rate_ ? quotient_or_infinity(k_, rate_) : product_or_infinity(k_, theta_);
}

double log_upper_gamma_q_cf(double k, double x, double* x_times_cf) {
  // Γ(k, x) = e^{−x} x^k · 1/(x+1−k − 1(1−k)/(x+3−k − 2(2−k)/(x+5−k − …))), evaluated by
  // modified Lentz; converges quickly for x ≥ k + 1.
  constexpr double kFpMin = 1e-300;
  constexpr double kEps = 1e-17;
  double b = x + 1.0 - k;
  double c = 1.0 / kFpMin;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - k);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kFpMin) d = kFpMin;
    c = b + an / c;
    if (std::fabs(c) < kFpMin) c = kFpMin;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEps) break;
  }
  if (x_times_cf != nullptr) *x_times_cf = x * h;
  return -x + k * std::log(x) - log_gamma(k) + std::log(h);
}

double GammaPath::transmittance(double t) const {
  const double x = t_over_theta(t);
  if (x == kInfinity) return 0.0;
  return regularized_gamma_q(k_, x);
}

double GammaPath::log_transmittance(double t) const {
  const double x = t_over_theta(t);
  if (x == 0.0) return 0.0;
  if (x == kInfinity) return -kInfinity;
  const double q = regularized_gamma_q(k_, x);
  if (q > 0.5) return std::log1p(-regularized_gamma_p(k_, x));  // Q ≈ 1: use P
  if (x >= k_ + 1.0 && !(q > kTinyQ)) return log_upper_gamma_q_cf(k_, x);
  return q > 0.0 ? std::log(q) : -kInfinity;
}

double GammaPath::pdf(double t) const {
  const double x = t_over_theta(t);
  if (x == kInfinity) return 0.0;
  if (x == 0.0) return k_ < 1.0 ? kInfinity : (k_ == 1.0 ? per_length(1.0) : 0.0);
  return per_length(gamma_density(k_, x));  // S.63
}

double GammaPath::hazard(double t) const {
  const double x = t_over_theta(t);
  if (x == 0.0) return pdf(0.0);
  if (x == kInfinity) return per_length(1.0);  // the limit of 1/(θ·x·CF)
  const double q = regularized_gamma_q(k_, x);
  if (x < k_ + 1.0 || q > kTinyQ) {
    if (!(q > 0.0)) return kInfinity;
    // Σ may exceed DBL_MAX near t = 0 for k < 1 and tiny θ: saturate (law.h), T > 0 here.
    const double theta_sigma = quotient_or_infinity(gamma_density(k_, x), q);
    return std::min(per_length(k_ >= 1.0 ? std::min(1.0, theta_sigma) : theta_sigma),
                    std::numeric_limits<double>::max());
  }
  // p/Q = [x^{k−1}e^{−x}/(θΓ(k))] / [x^k e^{−x} CF/Γ(k)] = 1/(θ·x·CF): no underflow.
  double x_cf = 1.0;
  (void)log_upper_gamma_q_cf(k_, x, &x_cf);
  // For k ≥ 1 the hazard rises to its limit 1/θ and never exceeds it: clamp the rounding, so
  // θ·Σ ≤ 1 cannot overflow for θ = 1/DBL_MAX.
  return per_length(k_ >= 1.0 ? std::min(1.0, 1.0 / x_cf) : 1.0 / x_cf);
}

double sample_standard_gamma(double k, Pcg32& rng) {
  if (k < 1.0) {
    // G(k) = G(k+1)·u^{1/k} (Marsaglia & Tsang, sec. 6); in logs so u^{1/k} does not
    // underflow before the product does.
    const double g = sample_standard_gamma(k + 1.0, rng);
    return std::exp(std::log(g) + std::log(rng.uniform_open()) / k);
  }
  const double d = k - 1.0 / 3.0;
  const double c = 1.0 / std::sqrt(9.0 * d);
  boost::random::normal_distribution<double> normal;
  for (;;) {
    double z = 0.0;
    double v = 0.0;
    do {
      z = normal(rng);
      v = 1.0 + c * z;
    } while (v <= 0.0);
    v = v * v * v;
    const double u = rng.uniform_open();
    const double z2 = z * z;
    if (u < 1.0 - 0.0331 * z2 * z2) return d * v;  // squeeze
    if (std::log(u) < 0.5 * z2 + d * (1.0 - v + std::log(v))) return d * v;
  }
}

double GammaPath::sample_marsaglia_tsang(Pcg32& rng) const { return length(sample_standard_gamma(k_, rng)); }

double GammaPath::sample_inversion(Pcg32& rng) const {
  // Invert whichever tail is smaller, so both tails keep full relative accuracy.
  const double u = rng.uniform_open();
  return length(u < 0.5 ? gamma_q_inverse(k_, u) : gamma_p_inverse(k_, 1.0 - u));
}

double GammaPath::sample(Pcg32& rng) const {
  return sampler_ == GammaSampler::inversion ? sample_inversion(rng) : sample_marsaglia_tsang(rng);
}

std::string GammaPath::sampler_choice() const {
  return sampler_ == GammaSampler::marsaglia_tsang ? std::string() : to_string(sampler_);
}

std::string GammaPath::sampling_method() const {
  return sampler_ == GammaSampler::inversion ? "inversion: theta*gamma_q_inv(k, u) (Boost.Math)"
                                             : "rejection: Marsaglia-Tsang 2000 (k < 1: G(k+1)*u^(1/k))";
}

std::shared_ptr<const Law> GammaPath::closed_form_scatterer_partner() const {
  if (k_ == 1.0) return std::make_shared<Exponential>(1.0 / theta_);
  return nullptr;
}

}  // namespace weft::transmittance
