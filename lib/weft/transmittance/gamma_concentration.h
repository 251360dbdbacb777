#pragma once
/// @file
/// @brief The gamma-concentration law of Jarabo et al. 2018 (Eq. 19–20, S.44–S.57).
///
/// Concentration C ~ Gamma(shape α, rate β) and extinction μ = σC give
/// T(t) = (1 + σt/β)^−α = (1 + μ̄t/α)^−α with mean extinction μ̄ = σα/β. α = +∞ (Var C = 0) is
/// exactly the exponential law e^{−μ̄t}.

#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// @brief Gamma-concentration transmittance, stored as mean extinction μ̄ [1/length] and shape α.
class GammaConcentration final : public Law {
 public:
  /// μ̄ ≥ 0 finite; α > 0, +∞ allowed (exponential limit).
  GammaConcentration(double mean_extinction, double alpha);

  /// Paper parametrisation: cross-section σ [1/length per unit concentration], α, rate β.
  static GammaConcentration from_sigma_alpha_beta(double sigma, double alpha, double beta);
  /// From concentration statistics: α = C̄²/Var C, β = C̄/Var C; Var C = 0 gives α = +∞.
  static GammaConcentration from_concentration(double sigma, double mean_concentration, double var_concentration);

  [[nodiscard]] double mean_extinction() const { return mean_extinction_; }
  [[nodiscard]] double alpha() const { return alpha_; }

  [[nodiscard]] std::string name() const override { return "gamma"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override {
    return {{"mean_extinction", mean_extinction_}, {"alpha", alpha_}};
  }
  [[nodiscard]] double transmittance(double t) const override;
  [[nodiscard]] double log_transmittance(double t) const override;
  [[nodiscard]] double pdf(double t) const override;
  [[nodiscard]] double hazard(double t) const override;
  /// Inversion of 1 − T: t = (α/μ̄)·expm1(E/α), E = −log(u) (the correct form of S.51).
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override {
    return "inversion: t = (alpha/mean_extinction)*expm1(-log(u)/alpha)";
  }
  /// ℓ = α/(μ̄(α − 1)) for α > 1, +∞ for α ≤ 1 (1/μ̄ at α = +∞).
  [[nodiscard]] double mean_free_path() const override;
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<GammaConcentration>(*this); }

  /// T_S = p_Q/p_Q(0) = (1 + μ̄t/α)^−(α+1): gamma again, shape α + 1, same scale α/μ̄.
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;
  /// T_Q = ∫_t^∞ T_S/ℓ_S = (1 + μ̄t/α)^−(α−1): shape α − 1, same scale (needs α > 1).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_source_partner() const override;

  /// @brief The supplement's p ∝ T density (S.55): T(t)/ℓ = (μ̄(α−1)/α)(1 + μ̄t/α)^−α.
  /// Throws weft::Error for α ≤ 1 (T is not integrable).
  [[nodiscard]] double pdf_proportional_to_transmittance(double t) const;
  /// @brief CDF of the p ∝ T density (S.56): 1 − (1 + μ̄t/α)^{1−α}.
  [[nodiscard]] double cdf_proportional_to_transmittance(double t) const;
  /// @brief Draws t ∝ T(t) (S.57): t = (α/μ̄)·expm1(E/(α − 1)); throws for α ≤ 1.
  [[nodiscard]] double sample_proportional_to_transmittance(Pcg32& rng) const;

  /// α·log1p(μ̄t/α) = −log T(t), evaluated without overflow, underflow or cancellation.
  [[nodiscard]] double optical_exponent(double t) const;

 private:
  void require_alpha_above_one(const char* what) const;
  double mean_extinction_;
  double alpha_;
  double inverse_alpha_;  ///< 1/α (0 at α = ∞), precomputed for the sampler
  double scale_;          ///< α/μ̄ [length]; +∞ where it overflows (sampler then takes the slow path)
};

}  // namespace weft::transmittance
