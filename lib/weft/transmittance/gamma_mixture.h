#pragma once
/// @file
/// @brief A finite mixture of gamma-concentration laws (statistics local across a beam; docs/transmittance.md).
///
/// The rays of a beam fall into groups (height layers of a sheet, coarse cells across it, or
/// "gap" and "yarn"); the rays of group i, a fraction w_i of the beam, see a gamma concentration
/// with shape α_i and mean extinction μ̄_i. T is the ray-weighted mean of the groups' laws:
///
///   T_Q(t) = Σ_i w_i (1 + μ̄_i t/α_i)^−α_i,  Σ_i w_i = 1.
///
/// μ̄_i = 0 is a gap component (its rays never collide: T(∞) = Σ_{μ̄_i=0} w_i, ℓ = ∞); α_i = ∞ is
/// an exponential component e^{−μ̄_i t}. docs/transmittance.md derives the reciprocal partners.

#include <vector>

#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// One group of rays: its share of the beam and its gamma law.
struct GammaComponent {
  double weight;           ///< w_i ≥ 0 [1]
  double mean_extinction;  ///< μ̄_i ≥ 0, finite [1/length]; 0 = a gap (never collides)
  double alpha;            ///< α_i > 0, +∞ allowed (exponential component) [1]
};

class GammaMixture final : public Law {
 public:
  /// At least one component; weights finite, ≥ 0 and summing to 1 within kWeightTolerance
  /// (they are then divided by their sum); each component valid as a gamma law. Throws
  /// weft::Error naming the component and the parameter otherwise.
  explicit GammaMixture(std::vector<GammaComponent> components);

  /// |Σ w_i − 1| allowed before normalisation (weights typed with 6 digits, or counts divided).
  static constexpr double kWeightTolerance = 1e-6;

  /// The components as given (weights normalised), including zero-weight ones.
  [[nodiscard]] const std::vector<GammaComponent>& components() const { return components_; }

  [[nodiscard]] std::string name() const override { return "gamma-mixture"; }
  /// weight_1, alpha_1, mean_extinction_1, weight_2, … (1-based, as the registry reads them).
  [[nodiscard]] std::vector<Parameter> parameters() const override;
  [[nodiscard]] double transmittance(double t) const override;
  /// log1p(−Σ w_i(1 − T_i)) while T > ½ (no cancellation near t = 0 or for gap fractions near
  /// 1), log-sum-exp of log w_i − α_i log1p(μ̄_i t/α_i) otherwise (no underflow).
  [[nodiscard]] double log_transmittance(double t) const override;
  /// p = Σ·T, with T in log space where it underflows.
  [[nodiscard]] double pdf(double t) const override;
  /// Σ = Σ_i ρ_i Σ_i(t), ρ_i = w_i T_i/T (softmax in log space): the hazards of the groups whose
  /// rays are still alive. At t = ∞ the limit: 0 if any component is a gap or has finite α,
  /// min μ̄_i if all are exponential.
  [[nodiscard]] double hazard(double t) const override;
  /// Composition: component i with probability w_i (one uniform), then its gamma flight
  /// (+∞ for a gap component).
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override {
    return "composition: component by weight, then gamma inversion";
  }
  /// ℓ = Σ w_i ℓ_i; +∞ if a component with w_i > 0 has ℓ_i = ∞ (a gap, or α_i ≤ 1).
  [[nodiscard]] double mean_free_path() const override;
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<GammaMixture>(*this); }

  /// T_S = p_Q/p_Q(0) = Σ w_i μ̄_i (1 + μ̄_i t/α_i)^−(α_i+1) / Σ w_i μ̄_i: a gamma mixture again,
  /// weights ∝ w_i μ̄_i (gap components drop out), component shapes α_i + 1.
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;
  /// T_Q = ∫_t^∞ T_S/ℓ_S = Σ (w_i ℓ_i/ℓ_S)(1 + μ̄_i t/α_i)^−(α_i−1): weights ∝ w_i ℓ_i, shapes
  /// α_i − 1 (exists when ℓ_S is finite: every component with w_i > 0 has μ̄_i > 0, α_i > 1).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_source_partner() const override;

 private:
  struct Active {
    double log_weight;
    GammaConcentration law;
  };
  std::vector<GammaComponent> components_;
  std::vector<Active> active_;        ///< the components with w_i > 0
  std::vector<double> cumulative_;    ///< Σ_{j≤i} w_j over active_, last entry forced to 1
  std::vector<double> weights_;       ///< w_i over active_
  double max_mean_extinction_ = 0.0;  ///< max μ̄_i over active_ (bounds every component's hazard)
};

}  // namespace weft::transmittance
