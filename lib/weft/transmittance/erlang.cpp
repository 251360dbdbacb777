#include "weft/transmittance/erlang.h"

#include <cmath>

#include <boost/math/special_functions/gamma.hpp>

#include "weft/core/error.h"
#include "weft/transmittance/exponential.h"

namespace weft::transmittance {

namespace {
int require_integer_shape(const char* law, double k) {
  if (!(std::isfinite(k) && k >= 1.0 && k == std::floor(k) && k <= 1e6)) {
    fail("{} law: k must be an integer in [1, 1e6], got {}", law, k);
  }
  return static_cast<int>(k);
}

double require_rate(const char* law, double rate) {
  if (!(std::isfinite(rate) && rate > 0.0)) fail("{} law: rate must be finite and > 0, got {}", law, rate);
  return rate;
}

double sum_of_exponentials(int k, double rate, Pcg32& rng) {
  double sum = 0.0;
  for (int i = 0; i < k; ++i) sum -= std::log(1.0 - rng.uniform());
  return sum / rate;
}

constexpr int kMaxDirectSum = 16;
}  // namespace

Erlang::Erlang(double k, double rate)
    : k_(require_integer_shape("erlang", k)), rate_(require_rate("erlang", rate)), gamma_(k_, 1.0 / rate_) {}

double Erlang::sample(Pcg32& rng) const {
  if (k_ <= kMaxDirectSum) return sum_of_exponentials(k_, rate_, rng);
  return sample_standard_gamma(k_, rng) / rate_;
}

std::string Erlang::sampling_method() const {
  return k_ <= kMaxDirectSum ? "sum of k exponential flights" : "rejection: Marsaglia-Tsang 2000";
}

std::shared_ptr<const Law> Erlang::closed_form_scatterer_partner() const {
  if (k_ == 1) return std::make_shared<Exponential>(rate_);
  return nullptr;
}

std::shared_ptr<const Law> Erlang::closed_form_source_partner() const {
  return std::make_shared<ErlangMixture>(k_, rate_);
}

ErlangMixture::ErlangMixture(double k, double rate)
    : k_(require_integer_shape("erlang-source", k)), rate_(require_rate("erlang-source", rate)) {}

double ErlangMixture::transmittance(double t) const {
  // ∫_t^∞ Q(k, λs) ds = (1/λ) Σ_{n<k} Q(n+1, λt): each Poisson term of Q(k, ·) integrates to
  // an Erlang survival function. Summed by Poisson terms: T = e^{−x} Σ_{n<k} (k−n)/k · x^n/n!,
  // all positive, so no cancellation; e^{−x} and x^n/n! ≤ e^x stay in range for x < 700.
  const double x = rate_ * t;
  if (x == kInfinity) return 0.0;
  if (x >= 700.0) return std::exp(log_transmittance(t));
  double term = 1.0;
  double sum = 0.0;
  for (int n = 0; n < k_; ++n) {
    sum += (static_cast<double>(k_ - n) / k_) * term;
    term *= x / (n + 1);
  }
  return std::exp(-x) * sum;
}

double ErlangMixture::log_transmittance(double t) const {
  const double x = rate_ * t;
  if (x == kInfinity) return -kInfinity;
  if (x < 0.5) {
    // T near 1: log1p of −(1/k) Σ P(j, x) keeps the digits that 1 − Σ Q would cancel.
    double lower = 0.0;
    for (int j = 1; j <= k_; ++j) lower += boost::math::gamma_p(static_cast<double>(j), x);
    return std::log1p(-lower / k_);
  }
  if (x < 700.0) return std::log(transmittance(t));
  // Deep tail: the same Poisson sum in log space.
  double log_sum = -kInfinity;
  for (int n = 0; n < k_; ++n) {
    const double term = std::log(static_cast<double>(k_ - n) / k_) + n * std::log(x) - std::lgamma(n + 1.0);
    const double hi = std::max(log_sum, term);
    log_sum = hi + std::log(std::exp(log_sum - hi) + std::exp(term - hi));
  }
  return -x + log_sum;
}

double ErlangMixture::pdf(double t) const {
  const double x = rate_ * t;
  if (x == kInfinity) return 0.0;
  return rate_ / k_ * boost::math::gamma_q(static_cast<double>(k_), x);
}

double ErlangMixture::hazard(double t) const {
  const double value = transmittance(t);
  if (value > 0.0) return pdf(t) / value;
  return rate_;  // both underflow: the slowest Erlang term dominates, whose hazard → λ
}

double ErlangMixture::sample(Pcg32& rng) const {
  const int j = 1 + static_cast<int>(rng.uniform_below(static_cast<std::uint32_t>(k_)));
  if (j <= kMaxDirectSum) return sum_of_exponentials(j, rate_, rng);
  return sample_standard_gamma(j, rng) / rate_;
}

std::shared_ptr<const Law> ErlangMixture::closed_form_scatterer_partner() const {
  return std::make_shared<Erlang>(k_, rate_);
}

}  // namespace weft::transmittance
