#pragma once
/// @file
/// @brief Gamma-distributed free paths (S.62–S.64): p(t) = Γ(t; k, θ), T(t) = Q(k, t/θ).

#include "weft/transmittance/law.h"

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
class GammaPath final : public Law {
 public:
  GammaPath(double k, double theta, GammaSampler sampler = GammaSampler::marsaglia_tsang);

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
  [[nodiscard]] double mean_free_path() const override { return k_ * theta_; }
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<GammaPath>(*this); }
  /// k = 1 is the exponential law, whose partner is itself; other k have none in closed form
  /// (as T_Q: p_Q(0) is 0 or +∞, so no partner exists at all).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;

  [[nodiscard]] double sample_marsaglia_tsang(Pcg32& rng) const;
  [[nodiscard]] double sample_inversion(Pcg32& rng) const;

 private:
  double k_;
  double theta_;
  GammaSampler sampler_;
};

/// @brief Standard Gamma(k, 1) variate by Marsaglia & Tsang (2000), k > 0 (k < 1 by the
/// G(k+1)·u^{1/k} boost, in log space so tiny k underflows to 0 only where the true value does).
[[nodiscard]] double sample_standard_gamma(double k, Pcg32& rng);

/// @brief log Q(k, x) for x ≥ k + 1 by the modified-Lentz continued fraction; also returns
/// x·CF(x) = x^{1−k} e^x Γ(k, x), whose inverse is θ·Σ.
[[nodiscard]] double log_upper_gamma_q_cf(double k, double x, double* x_times_cf = nullptr);

}  // namespace weft::transmittance
