#pragma once
/// @file
/// @brief Gamma-distributed free paths (S.62–S.64): p(t) = Γ(t; k, θ), T(t) = Q(k, t/θ).

#include "weft/transmittance/law.h"
#include "weft/transmittance/overflow.h"

namespace weft::transmittance {

/// How GammaPath::sample draws t.
enum class GammaSampler {
  marsaglia_tsang,  ///< Marsaglia & Tsang 2000 rejection; k < 1 via G(k+1)·u^{1/k}
  inversion,        ///< Boost.Math gamma_q_inv / gamma_p_inv of a uniform
};

[[nodiscard]] std::string to_string(GammaSampler sampler);
/// Parses "marsaglia-tsang" | "inversion"; throws weft::Error otherwise.
[[nodiscard]] GammaSampler parse_gamma_sampler(const std::string& text);

/// @brief Gamma free-path law with shape k > 0 and scale θ > 0 [length]; ℓ = kθ.
///
/// Valid range: any finite k > 0 and θ > 0. Where a quantity leaves the doubles it saturates
/// rather than turning NaN: ℓ = kθ and p may overflow to +∞, T and p underflow to 0 (log T and
/// Σ stay finite), and a draw beyond the largest double is returned as DBL_MAX (see law.h).
class GammaPath final : public Law {
 public:
  GammaPath(double k, double theta, GammaSampler sampler = GammaSampler::marsaglia_tsang);
  /// The same law given by its rate λ = 1/θ [1/length], as Erlang does: λt and λ·(…) are then
  /// evaluated with λ itself, exact even where 1/λ is subnormal (λ near DBL_MAX).
  static GammaPath from_rate(double k, double rate, GammaSampler sampler = GammaSampler::marsaglia_tsang);

  [[nodiscard]] double k() const { return k_; }
  [[nodiscard]] double theta() const { return theta_; }
  [[nodiscard]] GammaSampler sampler() const { return sampler_; }

  [[nodiscard]] std::string name() const override { return "gamma-path"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override { return {{"k", k_}, {"theta", theta_}}; }
  /// Q(k, t/θ), the regularised upper incomplete gamma function (S.62).
  [[nodiscard]] double transmittance(double t) const override;
  /// log Q, by Legendre's continued fraction where Q underflows.
  [[nodiscard]] double log_transmittance(double t) const override;
  [[nodiscard]] double pdf(double t) const override;
  /// Σ = p/Q (S.64); where both underflow Σ = 1/(θ·x·CF(x)) → 1/θ.
  [[nodiscard]] double hazard(double t) const override;
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override;
  [[nodiscard]] std::string sampler_choice() const override;
  /// kθ (k/λ when built from a rate); +∞ where it overflows.
  [[nodiscard]] double mean_free_path() const override;
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<GammaPath>(*this); }
  /// k = 1 is the exponential law, whose partner is itself; other k have none in closed form
  /// (as T_Q: p_Q(0) is 0 or +∞, so no partner exists at all).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;

  [[nodiscard]] double sample_marsaglia_tsang(Pcg32& rng) const;
  [[nodiscard]] double sample_inversion(Pcg32& rng) const;

 private:
  struct RateTag {};
  GammaPath(double k, double rate, GammaSampler sampler, RateTag);
  /// x = t/θ (or λt when built from a rate); +∞ where it overflows.
  [[nodiscard]] double t_over_theta(double t) const;
  /// v/θ [1/length] (or λv), for densities and hazards; +∞ where it overflows.
  [[nodiscard]] double per_length(double v) const;
  /// xθ [length] (or x/λ), for draws; DBL_MAX where it overflows.
  [[nodiscard]] double length(double x) const;
  double k_;
  double theta_;
  double rate_;  ///< 1/θ, or the given rate
  bool from_rate_ = false;
  GammaSampler sampler_;
};

/// Q(k, x), P(k, x) and the Gamma(k, 1) density x^{k−1}e^{−x}/Γ(k) (Boost.Math, underflow to 0,
/// overflow to +∞, FP exceptions held inside: see fp_hold.h), for k > 0 and x ≥ 0.
[[nodiscard]] double regularized_gamma_q(double k, double x);
[[nodiscard]] double regularized_gamma_p(double k, double x);
[[nodiscard]] double gamma_density(double k, double x);

/// @brief The quantiles of Gamma(k, 1): P⁻¹(k, p) and Q⁻¹(k, q), the x with P(k, x) = p or
/// Q(k, x) = q, for k > 0 and p, q in (0, 1) (Boost.Math's gamma_p_inv / gamma_q_inv with the
/// policy above). Above k = kLargeGammaShape they are the Cornish–Fisher expansion of the
/// quantile to O(k⁻²) (gamma_quantile_cornish_fisher), within rounding of Boost's where Boost
/// converges; Boost's iteration gives up for k beyond about 2·10¹⁰ (its series exceeds its
/// iteration limit), a shape a nearly uniform column or a user's law reaches.
[[nodiscard]] double gamma_p_inverse(double k, double p);
[[nodiscard]] double gamma_q_inverse(double k, double q);
inline constexpr double kLargeGammaShape = 1e8;
/// x/k at the standard normal quantile z of the probability (z < 0 in the lower tail):
/// 1 + z/√k + (z² − 1)/(3k) + (z³ − 7z)/(36k^{3/2}) − (3z⁴ + 7z² − 16)/(810k²). Its remainder is
/// O(k^{−5/2}); at k ≥ 10⁸ it is below one ulp for |z| ≤ 7 (test GammaQuantile.*).
[[nodiscard]] double gamma_quantile_cornish_fisher(double k, double z);

/// @brief Standard Gamma(k, 1) variate by Marsaglia & Tsang (2000), k > 0 (k < 1 by the
/// G(k+1)·u^{1/k} boost, in log space so tiny k underflows to 0 only where the true value does).
[[nodiscard]] double sample_standard_gamma(double k, Pcg32& rng);

/// @brief log Q(k, x) for x ≥ k + 1 by the modified-Lentz continued fraction; also returns
/// x·CF(x) = x^{1−k} e^x Γ(k, x), whose inverse is θ·Σ.
[[nodiscard]] double log_upper_gamma_q_cf(double k, double x, double* x_times_cf = nullptr);

}  // namespace weft::transmittance
