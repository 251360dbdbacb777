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

 private:
  /// 1 − μ̄t with a single rounding (fma), so t just below 1/μ̄ keeps its tiny remainder.
  [[nodiscard]] double remainder(double t) const;
  double mean_extinction_;
};

}  // namespace weft::transmittance
