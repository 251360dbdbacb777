#pragma once
/// @file
/// @brief Perfect negative correlation (S.58–S.61): T(t) = max(0, 1 − μ̄t).

#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// @brief Linear transmittance with mean extinction μ̄ ≥ 0 [1/length]; support [0, 1/μ̄).
///
/// Beyond 1/μ̄, T = p = 0 and Σ = +∞ (the supplement's S.60 writes 0 there; the hazard's limit
/// from the left is +∞, and Law's contract asks +∞ where T = 0).
class Linear final : public Law {
 public:
  explicit Linear(double mean_extinction);

  [[nodiscard]] double mean_extinction() const { return mean_extinction_; }

  [[nodiscard]] std::string name() const override { return "linear"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override { return {{"mean_extinction", mean_extinction_}}; }
  [[nodiscard]] double transmittance(double t) const override;
  [[nodiscard]] double log_transmittance(double t) const override;
  [[nodiscard]] double pdf(double t) const override;
  [[nodiscard]] double hazard(double t) const override;
  /// Inversion (S.61): t = ξ/μ̄.
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override { return "inversion: t = u/mean_extinction"; }
  /// ℓ = 1/(2μ̄).
  [[nodiscard]] double mean_free_path() const override;
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<Linear>(*this); }
  /// The reciprocal partner in closed form: T_S = p_Q/p_Q(0), a step (LinearScatterer).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;

 private:
  /// 1 − μ̄t with a single rounding (fma), so t just below 1/μ̄ keeps its tiny remainder.
  [[nodiscard]] double remainder(double t) const;
  double mean_extinction_;
};

/// @brief Reciprocal scatterer partner of Linear (docs/render.md §2): p_Q = μ̄ on [0, t_end)
/// gives T_S(t) = p_Q(t)/p_Q(0) = 1 for t < t_end and 0 beyond, ℓ_S = t_end = 1/μ̄.
///
/// The law is singular: all its probability is one atom at t_end (a flight from a scatterer
/// always travels exactly t_end), so it has no density. pdf() returns the density of its
/// absolutely continuous part, 0; nothing may divide by it. The path tracer never does: in
/// reciprocal mode a scatterer flight is drawn from this law and weighted by the same law, so
/// its weight is exactly 1 (the ratio of one measure to itself), not a ratio of densities.
/// t_end is the first double at which Linear's own p_Q is 0, so T_S = p_Q/p_Q(0) holds at
/// every double, including the rounding of 1/μ̄.
class LinearScatterer final : public Law {
 public:
  explicit LinearScatterer(double mean_extinction);

  [[nodiscard]] double mean_extinction() const { return mean_extinction_; }
  /// Where the atom sits (+∞ for μ̄ = 0).
  [[nodiscard]] double end() const { return end_; }

  [[nodiscard]] std::string name() const override { return "linear/scatterer"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override { return {{"mean_extinction", mean_extinction_}}; }
  [[nodiscard]] double transmittance(double t) const override { return t < end_ ? 1.0 : 0.0; }
  [[nodiscard]] double log_transmittance(double t) const override { return t < end_ ? 0.0 : -kInfinity; }
  /// 0: the law has no density (a point mass at end()).
  [[nodiscard]] double pdf(double /*t*/) const override { return 0.0; }
  /// 0 before the atom, +∞ from it on (where T = 0).
  [[nodiscard]] double hazard(double t) const override { return t < end_ ? 0.0 : kInfinity; }
  /// Always end(): the point mass.
  [[nodiscard]] double sample(Pcg32& /*rng*/) const override { return end_; }
  [[nodiscard]] std::string sampling_method() const override { return "point mass: t = 1/mean_extinction"; }
  /// ℓ_S = ∫T_S = end().
  [[nodiscard]] double mean_free_path() const override { return end_; }
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<LinearScatterer>(*this); }
  /// T_Q(t) = ∫_t^∞ T_S/ℓ_S = Linear(μ̄).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_source_partner() const override;

 private:
  double mean_extinction_;
  double end_;
};

}  // namespace weft::transmittance
