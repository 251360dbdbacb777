#include "weft/transmittance/gamma_path.h"

#include <cmath>

#include <boost/math/special_functions/gamma.hpp>
#include <boost/random/normal_distribution.hpp>

#include "weft/core/error.h"
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

std::string to_string(GammaSampler sampler) {
  return sampler == GammaSampler::marsaglia_tsang ? "marsaglia-tsang" : "inversion";
}

GammaSampler parse_gamma_sampler(const std::string& text) {
  if (text == "marsaglia-tsang" || text.empty()) return GammaSampler::marsaglia_tsang;
  if (text == "inversion") return GammaSampler::inversion;
  fail("gamma-path law: unknown sampler '{}' (known: marsaglia-tsang, inversion)", text);
}

GammaPath::GammaPath(double k, double theta, GammaSampler sampler) : k_(k), theta_(theta), sampler_(sampler) {
  if (!(std::isfinite(k) && k > 0.0)) fail("gamma-path law: k must be finite and > 0, got {}", k);
  if (!(std::isfinite(theta) && theta > 0.0)) fail("gamma-path law: theta must be finite and > 0, got {}", theta);
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
  return -x + k * std::log(x) - boost::math::lgamma(k, kPolicy) + std::log(h);
}

double GammaPath::transmittance(double t) const {
  const double x = t / theta_;
  if (x == kInfinity) return 0.0;
  return boost::math::gamma_q(k_, x, kPolicy);
}

double GammaPath::log_transmittance(double t) const {
  const double x = t / theta_;
  if (x == 0.0) return 0.0;
  if (x == kInfinity) return -kInfinity;
  const double q = boost::math::gamma_q(k_, x, kPolicy);
  if (q > 0.5) return std::log1p(-boost::math::gamma_p(k_, x, kPolicy));  // Q ≈ 1: use P
  if (q > kTinyQ || x < k_ + 1.0) return std::log(q);
  return log_upper_gamma_q_cf(k_, x);
}

double GammaPath::pdf(double t) const {
  const double x = t / theta_;
  if (x == kInfinity) return 0.0;
  if (x == 0.0) return k_ < 1.0 ? kInfinity : (k_ == 1.0 ? 1.0 / theta_ : 0.0);
  return boost::math::gamma_p_derivative(k_, x, kPolicy) / theta_;  // S.63
}

double GammaPath::hazard(double t) const {
  const double x = t / theta_;
  if (x == 0.0) return pdf(0.0);
  if (x == kInfinity) return 1.0 / theta_;  // the limit of 1/(θ·x·CF)
  const double q = boost::math::gamma_q(k_, x, kPolicy);
  if (q > kTinyQ || x < k_ + 1.0) return boost::math::gamma_p_derivative(k_, x, kPolicy) / theta_ / q;
  // p/Q = [x^{k−1}e^{−x}/(θΓ(k))] / [x^k e^{−x} CF/Γ(k)] = 1/(θ·x·CF): no underflow.
  double x_cf = 1.0;
  (void)log_upper_gamma_q_cf(k_, x, &x_cf);
  return 1.0 / (theta_ * x_cf);
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

double GammaPath::sample_marsaglia_tsang(Pcg32& rng) const { return theta_ * sample_standard_gamma(k_, rng); }

double GammaPath::sample_inversion(Pcg32& rng) const {
  // Invert whichever tail is smaller, so both tails keep full relative accuracy.
  const double u = rng.uniform_open();
  const double x = u < 0.5 ? boost::math::gamma_q_inv(k_, u, kPolicy) : boost::math::gamma_p_inv(k_, 1.0 - u, kPolicy);
  return theta_ * x;
}

double GammaPath::sample(Pcg32& rng) const {
  return sampler_ == GammaSampler::inversion ? sample_inversion(rng) : sample_marsaglia_tsang(rng);
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
