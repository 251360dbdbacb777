#pragma once
/// @file
/// @brief The transmittance-law interface: T(t), p(t), Σ(t), log T, sampling, mean free path.
///
/// A law describes free flight along a ray through a statistically homogeneous medium:
/// T(t) is the probability of reaching distance t ≥ 0 without extinction, p(t) = −dT/dt the
/// free-flight pdf, Σ(t) = p/T the hazard ("differential probability of extinction", S.5).
/// One file per law implements this interface; registry.h maps names to laws (Tungsten-style).

#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "weft/core/rng.h"

namespace weft::transmittance {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// A named scalar parameter of a law, as shown by `weft model --json` and scene files.
struct Parameter {
  std::string name;
  double value;
};

class Law {
 public:
  virtual ~Law() = default;

  /// Registry name ("exponential", "gamma", ...).
  [[nodiscard]] virtual std::string name() const = 0;
  /// The law's parameters in its canonical parametrisation (round-trips through the registry).
  [[nodiscard]] virtual std::vector<Parameter> parameters() const = 0;

  /// T(t) for t ≥ 0, in [0, 1], non-increasing; T(+∞) = 0 unless the law has an atom at ∞.
  [[nodiscard]] virtual double transmittance(double t) const = 0;
  /// log T(t), accurate where T underflows (−∞ where T is exactly 0).
  [[nodiscard]] virtual double log_transmittance(double t) const = 0;
  /// p(t) = −dT/dt.
  [[nodiscard]] virtual double pdf(double t) const = 0;
  /// Σ(t) = p(t)/T(t), finite wherever T > 0 even if both underflow (saturating at DBL_MAX
  /// where the exact hazard exceeds it, e.g. λ = DBL_MAX); +∞ where T = 0.
  [[nodiscard]] virtual double hazard(double t) const = 0;

  /// Draws t ~ p; returns +∞ for the probability mass that never collides (e.g. μ = 0). A draw
  /// that collides beyond the largest double (possible only where T(DBL_MAX) > 0, e.g. rates
  /// near DBL_MIN) is returned as DBL_MAX, not +∞: it is farther than any scene, yet finite.
  [[nodiscard]] virtual double sample(Pcg32& rng) const = 0;
  /// How `sample` works, for reports ("inversion", "Marsaglia-Tsang", ...).
  [[nodiscard]] virtual std::string sampling_method() const = 0;
  /// The sampler chosen where the law offers several (LawSpec::sampler: gamma-path's
  /// "inversion"); empty for the default one, so spec_of round-trips the choice.
  [[nodiscard]] virtual std::string sampler_choice() const { return {}; }

  /// ℓ = ∫₀^∞ T(t) dt; +∞ when the integral diverges.
  [[nodiscard]] virtual double mean_free_path() const = 0;

  [[nodiscard]] virtual std::unique_ptr<Law> clone() const = 0;

  /// @brief Closed-form reciprocal partner when this law is T_Q: T_S(t) = p_Q(t)/p_Q(0).
  /// nullptr when the law has none (TransmittancePair then derives it numerically); only
  /// called once the pair has checked that p_Q(0) is finite and > 0.
  [[nodiscard]] virtual std::shared_ptr<const Law> closed_form_scatterer_partner() const { return nullptr; }
  /// @brief Closed-form reciprocal partner when this law is T_S: T_Q(t) = ∫_t^∞ T_S/ℓ_S.
  /// nullptr when the law has none; only called once ℓ_S is known to be finite.
  [[nodiscard]] virtual std::shared_ptr<const Law> closed_form_source_partner() const { return nullptr; }
};

using LawPtr = std::shared_ptr<const Law>;

}  // namespace weft::transmittance
