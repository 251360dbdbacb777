#pragma once
/// @file
/// @brief Numerically derived reciprocal partners (docs/architecture.md §6), for laws without a closed form.
///
/// p_Q(t) = T_S(t)/ℓ_S ties the source law Q to the scatterer law S. From a given T_Q,
/// T_S = p_Q/p_Q(0); from a given T_S, T_Q(t) = ∫_t^∞ T_S/ℓ_S.

#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// @brief T_S(t) = p_Q(t)/p_Q(0) from a given source law; p_S by finite differences of p_Q,
/// sampling by inverting T_S (TOMS 748), ℓ_S = (1 − T_Q(∞))/p_Q(0).
class ScattererFromSource final : public Law {
 public:
  /// Throws weft::Error if p_Q(0) is not finite and > 0 (or ℓ_S = 1/p_Q(0) not a normal
  /// double), or p_Q increases somewhere (then p_Q/p_Q(0) is not a transmittance): checked on a
  /// grid, and exactly at every sample of a tabulated law, whose p_Q jumps there (a table is
  /// a valid source law only if it is convex: its interval hazards do not increase).
  explicit ScattererFromSource(LawPtr source);

  [[nodiscard]] std::string name() const override { return source_->name() + "/scatterer"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override { return source_->parameters(); }
  [[nodiscard]] double transmittance(double t) const override;
  [[nodiscard]] double log_transmittance(double t) const override;
  [[nodiscard]] double pdf(double t) const override;
  [[nodiscard]] double hazard(double t) const override;
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override { return "numerical inversion of p_Q/p_Q(0)"; }
  /// ℓ_S = (1 − T_Q(∞))/p_Q(0): 1/p_Q(0) unless the source law has a plateau.
  [[nodiscard]] double mean_free_path() const override;
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<ScattererFromSource>(*this); }
  [[nodiscard]] std::shared_ptr<const Law> closed_form_source_partner() const override { return source_; }

 private:
  LawPtr source_;
  double p0_;
};

/// @brief T_Q(t) = ∫_t^∞ T_S/ℓ_S from a given scatterer law: p_Q = T_S/ℓ_S exactly, T_Q by
/// Gauss–Legendre quadrature over a tabulated grid (exp-sinh beyond it), sampling by
/// inversion (table search, then TOMS 748 inside the interval).
class SourceFromScatterer final : public Law {
 public:
  /// Throws weft::Error if ℓ_S is not finite and ≥ DBL_MIN (1/ℓ_S, the scale of p_Q, must be
  /// representable).
  explicit SourceFromScatterer(LawPtr scatterer);

  [[nodiscard]] std::string name() const override { return scatterer_->name() + "/source"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override { return scatterer_->parameters(); }
  [[nodiscard]] double transmittance(double t) const override;
  [[nodiscard]] double log_transmittance(double t) const override;
  [[nodiscard]] double pdf(double t) const override;
  [[nodiscard]] double hazard(double t) const override;
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override { return "numerical inversion of the integrated T_S"; }
  [[nodiscard]] double mean_free_path() const override { return mean_free_path_; }
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<SourceFromScatterer>(*this); }
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override { return scatterer_; }

 private:
  // Internally depths are u = t/ℓ_S, so the tables stay O(1) for any scale of the law.
  [[nodiscard]] double t_s(double u) const;                   ///< T_S(u·ℓ_S)
  [[nodiscard]] double integral_to_infinity(double u) const;  ///< ∫_u^∞ T_S(vℓ_S) dv
  [[nodiscard]] double sample_scaled(Pcg32& rng) const;       ///< a draw of u = t/ℓ_S
  LawPtr scatterer_;
  double scale_ = 1.0;        ///< ℓ_S as the law states it [length], a normal double
  double ell_u_ = 1.0;        ///< ∫_0^∞ T_S(uℓ_S) du as integrated (≈ 1)
  std::vector<double> grid_;  ///< 0 = u_0 < … < u_N
  std::vector<double> tail_;  ///< ∫_{u_i}^∞ T_S(vℓ_S) dv
  double mean_free_path_ = 0.0;
};

}  // namespace weft::transmittance
