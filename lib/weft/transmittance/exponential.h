#pragma once
/// @file
/// @brief Classic Beer–Lambert free flight: T(t) = e^{−μt} (S.42–S.43).

#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// @brief Exponential law with extinction μ ≥ 0 [1/length]; μ = 0 is a vacuum (T ≡ 1).
class Exponential final : public Law {
 public:
  /// Throws weft::Error unless μ is finite and ≥ 0.
  explicit Exponential(double mu);

  [[nodiscard]] double mu() const { return mu_; }

  [[nodiscard]] std::string name() const override { return "exponential"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override { return {{"mu", mu_}}; }
  [[nodiscard]] double transmittance(double t) const override;
  [[nodiscard]] double log_transmittance(double t) const override;
  [[nodiscard]] double pdf(double t) const override;
  [[nodiscard]] double hazard(double t) const override;
  /// Inversion: t = −log(u)/μ with u ∈ (0, 1]; +∞ when μ = 0.
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override { return "inversion: t = -log(u)/mu"; }
  /// ℓ = 1/μ (+∞ for μ = 0).
  [[nodiscard]] double mean_free_path() const override;
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<Exponential>(*this); }
  /// The exponential law is its own reciprocal partner: p_Q/p_Q(0) = e^{−μt}, ∫_t^∞ e^{−μs}μ ds = e^{−μt}
  /// (μ = 0 never gets here: the pair refuses p_Q(0) = 0 and ℓ = ∞ first).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override {
    return std::make_shared<Exponential>(*this);
  }
  [[nodiscard]] std::shared_ptr<const Law> closed_form_source_partner() const override {
    return std::make_shared<Exponential>(*this);
  }

 private:
  double mu_;
};

}  // namespace weft::transmittance
