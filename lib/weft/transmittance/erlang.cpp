#include "weft/transmittance/erlang.h"

#include <algorithm>
#include <cmath>

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
  return saturating_quotient(sum, rate);  // DBL_MAX beyond the largest double (law.h)
}

/// The Poisson sums of x behind both Erlang laws, scaled by their largest term e^m:
/// a = Σ_{n<k} x^n/n! / e^m and b = Σ_{n<k} (k − n) x^n/n! / e^m, so that
/// Q(k, x) = e^{m−x}·a (the Erlang T) and Σ_j Q(j, x) = e^{m−x}·b (k times the mixture's T).
/// Summing outwards from the largest term (n = min(k − 1, ⌊x⌋)) by term ratios neither
/// overflows nor underflows for any x > 0, and stops once the terms are negligible, so the cost
/// is O(√x) terms near the peak, not O(k).
struct PoissonSums {
  double log_peak;  ///< m = log(x^n/n!) at the largest term
  double a;
  double b;
};

PoissonSums poisson_sums(int k, double x) {
  const int peak = static_cast<int>(std::min(static_cast<double>(k - 1), std::floor(x)));
  PoissonSums s{peak * std::log(x) - std::lgamma(peak + 1.0), 1.0, static_cast<double>(k - peak)};
  constexpr double kNegligible = 1e-18;
  double term = 1.0;
  for (int n = peak - 1; n >= 0; --n) {  // x^n/n! = x^{n+1}/(n+1)! · (n+1)/x
    term *= (n + 1) / x;
    s.a += term;
    s.b += (k - n) * term;
    if (term * k < kNegligible * s.a) break;  // the rest, even weighted by k − n ≤ k, is below 1e−18
  }
  term = 1.0;
  for (int n = peak + 1; n < k; ++n) {  // x^n/n! = x^{n−1}/(n−1)! · x/n, x/n < 1 past the peak
    term *= x / n;
    s.a += term;
    s.b += (k - n) * term;
    if (term < kNegligible * s.a) break;  // the weights k − n only fall from here
  }
  return s;
}

/// Above this k, for 0.5 ≤ x ≤ k, the mixture is evaluated from incomplete gamma functions
/// (O(1) per call) rather than Poisson sums (O(√x) terms): Σ_{n<k} (k − n) x^n/n! e^{−x}
/// = k Q(k, x) − x Q(k − 1, x) (since n x^n/n! = x·x^{n−1}/(n−1)!) and Q(k, x) = Q(k − 1, x) +
/// x^{k−1}e^{−x}/(k−1)!, so T = (1 − x/k) Q(k − 1, x) + Γ-density(k, x), both terms ≥ 0 for
/// x ≤ k, and 1 − T = P(k, x) + (x/k) Q(k − 1, x), both ≥ 0 (no cancellation either way).
constexpr int kLargeK = 64;

struct LargeKSplit {
  double t;            ///< T
  double one_minus_t;  ///< 1 − T
};

LargeKSplit large_k_mixture(int k, double x) {
  const double q_below = regularized_gamma_q(k - 1.0, x);
  return {(1.0 - x / k) * q_below + gamma_density(k, x), regularized_gamma_p(k, x) + (x / k) * q_below};
}

bool use_large_k(int k, double x) { return k > kLargeK && x >= 0.5 && x <= k; }

/// 1 − T of the mixture for x = λt < 0.5: e^{−x} Σ_{n≥1} min(n, k)/k · x^n/n! (the stages j ≤ n
/// of the mixture that a Poisson count n has finished), all terms positive, so no cancellation.
double one_minus_t_near_zero(int k, double x) {
  double term = 1.0;
  double sum = 0.0;
  for (int n = 1; n < 200; ++n) {
    term *= x / n;
    sum += (std::min(n, k) / static_cast<double>(k)) * term;
    if (term < 1e-18 * sum) break;
  }
  return std::exp(-x) * sum;
}

constexpr int kMaxDirectSum = 16;
}  // namespace

Erlang::Erlang(double k, double rate)
    : k_(require_integer_shape("erlang", k)),
      rate_(require_rate("erlang", rate)),
      gamma_(GammaPath::from_rate(k_, rate_)) {}

double Erlang::sample(Pcg32& rng) const {
  if (k_ <= kMaxDirectSum) return sum_of_exponentials(k_, rate_, rng);
  return saturating_quotient(sample_standard_gamma(k_, rng), rate_);
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
  const double x = product_or_infinity(rate_, t);
  if (x == 0.0) return 1.0;
  if (x == kInfinity) return 0.0;
  if (x < 0.5) return 1.0 - one_minus_t_near_zero(k_, x);
  if (use_large_k(k_, x)) return std::min(1.0, large_k_mixture(k_, x).t);
  // ∫_t^∞ Q(k, λs) ds = (1/λ) Σ_{n<k} Q(n+1, λt): each Poisson term of Q(k, ·) integrates to
  // an Erlang survival function, so T = e^{−x} Σ_{n<k} (k−n)/k · x^n/n! = e^{m−x}·b/k.
  const PoissonSums s = poisson_sums(k_, x);
  return std::exp(s.log_peak - x) * (s.b / k_);
}

double ErlangMixture::log_transmittance(double t) const {
  const double x = product_or_infinity(rate_, t);
  if (x == 0.0) return 0.0;
  if (x == kInfinity) return -kInfinity;
  if (x < 0.5) return std::log1p(-one_minus_t_near_zero(k_, x));  // log1p keeps the digits of T ≈ 1
  if (use_large_k(k_, x)) {
    const LargeKSplit m = large_k_mixture(k_, x);
    return std::min(0.0, m.one_minus_t < 0.5 ? std::log1p(-m.one_minus_t) : std::log(m.t));
  }
  const PoissonSums s = poisson_sums(k_, x);
  return s.log_peak - x + std::log(s.b / k_);
}

double ErlangMixture::pdf(double t) const {
  // p = λ/k · Q(k, λt) = T_S/ℓ_S; Q = e^{m−x}·a ≤ 1, so p ≤ λ/k never overflows.
  const double x = product_or_infinity(rate_, t);
  if (x == kInfinity) return 0.0;
  if (x == 0.0) return rate_ / k_;
  if (use_large_k(k_, x)) return (rate_ / k_) * std::min(1.0, regularized_gamma_q(k_, x));
  const PoissonSums s = poisson_sums(k_, x);
  return (rate_ / k_) * std::min(1.0, std::exp(s.log_peak - x) * s.a);
}

double ErlangMixture::hazard(double t) const {
  // Σ = p/T = λ·Q(k, x)/Σ_j Q(j, x) = λ·a/b: the e^{m−x} cancels, so Σ stays finite (≤ λ,
  // since b ≥ a) where T and p both underflow; at x = ∞ it is the limit λ·1/1.
  const double x = product_or_infinity(rate_, t);
  if (x == 0.0) return rate_ / k_;
  if (x == kInfinity) return rate_;
  if (use_large_k(k_, x)) {
    // T = (1 − x/k)Q(k − 1, x) + density(k, x) > 0 for x ≤ k (≈ 1/√(2πk) at worst, x = k).
    return rate_ * std::min(1.0, regularized_gamma_q(k_, x) / (k_ * large_k_mixture(k_, x).t));
  }
  const PoissonSums s = poisson_sums(k_, x);
  return rate_ * std::min(1.0, s.a / s.b);
}

double ErlangMixture::sample(Pcg32& rng) const {
  const int j = 1 + static_cast<int>(rng.uniform_below(static_cast<std::uint32_t>(k_)));
  if (j <= kMaxDirectSum) return sum_of_exponentials(j, rate_, rng);
  return saturating_quotient(sample_standard_gamma(j, rng), rate_);
}

std::shared_ptr<const Law> ErlangMixture::closed_form_scatterer_partner() const {
  return std::make_shared<Erlang>(k_, rate_);
}

}  // namespace weft::transmittance
