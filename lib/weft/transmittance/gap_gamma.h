#pragma once
/// @file
/// @brief The gap-aware gamma law (docs/transmittance.md): a fraction f₀ of rays sees no fibre, the rest a
/// gamma concentration.
///
///   T_Q(t) = f₀ + (1 − f₀)(1 + μ̄_c t/α)^−α,  f₀ ∈ [0, 1),
///
/// with μ̄_c the mean extinction of the rays that do see fibre (the non-gap part; the beam's
/// overall mean extinction is (1 − f₀)μ̄_c). f₀ is the open area of the cloth at the scale of
/// the statistics (1 − the textile "cover factor"). T(∞) = f₀, so ℓ_Q = ∞ for f₀ > 0 and the
/// sampler returns "no collision" (+∞) with probability f₀.
///
/// One implementation: this is the two-component GammaMixture {(f₀, gap), (1 − f₀, α, μ̄_c)} with
/// its own name and parameters. Its scatterer partner has no gap (a scatterer sits in a yarn):
/// T_S = p_Q/p_Q(0) = (1 + μ̄_c t/α)^−(α+1), the gamma law's own partner (docs/transmittance.md).

#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_mixture.h"
#include "weft/transmittance/law.h"

namespace weft::transmittance {

class GapGamma final : public Law {
 public:
  /// gap f₀ ∈ [0, 1); mean_extinction μ̄_c ≥ 0 finite [1/length]; α > 0, +∞ allowed.
  GapGamma(double gap, double mean_extinction, double alpha);

  /// The paper's parametrisation of the non-gap part, T = f₀ + (1 − f₀)(1 + σt/β)^−α.
  static GapGamma from_sigma_alpha_beta(double gap, double sigma, double alpha, double beta);
  /// From the concentration statistics of the non-gap rays: α = C̄_c²/Var C_c, μ̄_c = σC̄_c.
  static GapGamma from_concentration(double gap, double sigma, double mean_concentration, double var_concentration);

  [[nodiscard]] double gap() const { return gap_; }
  [[nodiscard]] double mean_extinction() const { return fibre_.mean_extinction(); }
  [[nodiscard]] double alpha() const { return fibre_.alpha(); }
  /// The law of the rays that see fibre, (1 + μ̄_c t/α)^−α.
  [[nodiscard]] const GammaConcentration& fibre_law() const { return fibre_; }

  [[nodiscard]] std::string name() const override { return "gap-gamma"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override {
    return {{"gap", gap_}, {"mean_extinction", fibre_.mean_extinction()}, {"alpha", fibre_.alpha()}};
  }
  [[nodiscard]] double transmittance(double t) const override { return mixture_.transmittance(t); }
  /// log(f₀ + (1 − f₀)e^{−α log1p(x)}): log1p(−(1 − f₀)(−expm1(−α log1p x))) while T > ½, log-sum-exp
  /// beyond (GammaMixture::log_transmittance).
  [[nodiscard]] double log_transmittance(double t) const override { return mixture_.log_transmittance(t); }
  /// p = (1 − f₀)μ̄_c(1 + x)^−(α+1).
  [[nodiscard]] double pdf(double t) const override { return mixture_.pdf(t); }
  /// Σ = p/T = (1 − f₀)μ̄_c(1 + x)^−(α+1)/T; → 0 as t → ∞ for f₀ > 0 (only gap rays survive).
  [[nodiscard]] double hazard(double t) const override { return mixture_.hazard(t); }
  /// +∞ ("no collision") with probability f₀, else the gamma flight t = (α/μ̄_c)·expm1(E/α).
  [[nodiscard]] double sample(Pcg32& rng) const override { return mixture_.sample(rng); }
  [[nodiscard]] std::string sampling_method() const override {
    return "composition: no collision (inf) with probability gap, else gamma inversion";
  }
  /// +∞ for f₀ > 0 (T(∞) = f₀: a gap ray never collides); the gamma law's ℓ for f₀ = 0.
  [[nodiscard]] double mean_free_path() const override { return mixture_.mean_free_path(); }
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<GapGamma>(*this); }

  /// T_S = (1 + μ̄_c t/α)^−(α+1): the gamma law with shape α + 1, mean extinction μ̄_c(α + 1)/α.
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;
  /// Only for f₀ = 0 (the gamma law's, shape α − 1); for f₀ > 0 as T_S, ℓ_S = ∞ and the pair refuses.
  [[nodiscard]] std::shared_ptr<const Law> closed_form_source_partner() const override;

 private:
  double gap_;
  GammaConcentration fibre_;
  GammaMixture mixture_;
};

}  // namespace weft::transmittance
