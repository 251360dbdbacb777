#pragma once
/// @file
/// @brief Erlang free paths: gamma-path with integer shape k and rate λ = 1/θ.
///
/// T(t) = e^{−λt} Σ_{n<k} (λt)^n/n! = Q(k, λt). k = 2, λ = 1 is d'Eon's Gamma-2 correlated
/// law T_c(s) = (1 + s)e^{−s}; k = 1 is the exponential law.

#include "weft/transmittance/gamma_path.h"

namespace weft::transmittance {

/// @brief Erlang(k, λ) law: the sum of k exponential flights of rate λ [1/length].
///
/// Valid range: integer k in [1, 1e6] and any finite λ > 0 (DBL_MIN ... DBL_MAX): λt is
/// evaluated with λ itself, T and p underflow to 0 while log T and Σ ≤ λ stay finite, ℓ = k/λ
/// becomes +∞ where it overflows and draws beyond the largest double are DBL_MAX (law.h).
class Erlang final : public Law {
 public:
  /// k must be an integer in [1, 1e6] (given as double for the registry), λ finite > 0;
  /// throws weft::Error otherwise.
  Erlang(double k, double rate);

  [[nodiscard]] int k() const { return k_; }
  [[nodiscard]] double rate() const { return rate_; }
  /// The same law as a gamma-path law (shape k, scale 1/λ).
  [[nodiscard]] const GammaPath& as_gamma_path() const { return gamma_; }

  [[nodiscard]] std::string name() const override { return "erlang"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override {
    return {{"k", static_cast<double>(k_)}, {"rate", rate_}};
  }
  [[nodiscard]] double transmittance(double t) const override { return gamma_.transmittance(t); }
  [[nodiscard]] double log_transmittance(double t) const override { return gamma_.log_transmittance(t); }
  [[nodiscard]] double pdf(double t) const override { return gamma_.pdf(t); }
  [[nodiscard]] double hazard(double t) const override { return gamma_.hazard(t); }
  /// Sum of k exponential flights −log(u_i)/λ for k ≤ 16, Marsaglia–Tsang beyond.
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override;
  /// ℓ = k/λ (+∞ where it overflows the doubles).
  [[nodiscard]] double mean_free_path() const override { return gamma_.mean_free_path(); }
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<Erlang>(*this); }
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;
  /// T_Q = ∫_t^∞ T_S/ℓ_S = (1/k) Σ_{j=1..k} Q(j, λt): an equal mixture of Erlang(1..k)
  /// (d'Eon's T_u(s) = (1 + s/2)e^{−s} for k = 2).
  [[nodiscard]] std::shared_ptr<const Law> closed_form_source_partner() const override;

 private:
  int k_;
  double rate_;
  GammaPath gamma_;
};

/// @brief Equal mixture of Erlang(j, λ), j = 1..k: the source law reciprocal to Erlang(k, λ).
///
/// Same valid range as Erlang. T, p and Σ come from Poisson sums scaled by their largest term
/// (or, for k > 64 and 0.5 ≤ λt ≤ k, from incomplete gamma functions, O(1) per call), written
/// so that no term cancels or overflows for any k in range and any λt.
class ErlangMixture final : public Law {
 public:
  ErlangMixture(double k, double rate);

  [[nodiscard]] std::string name() const override { return "erlang-source"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override {
    return {{"k", static_cast<double>(k_)}, {"rate", rate_}};
  }
  [[nodiscard]] double transmittance(double t) const override;
  [[nodiscard]] double log_transmittance(double t) const override;
  /// p = λ/k · Q(k, λt) = T_S/ℓ_S.
  [[nodiscard]] double pdf(double t) const override;
  [[nodiscard]] double hazard(double t) const override;
  /// Composition: pick j uniformly in 1..k, then an Erlang(j, λ) flight.
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override {
    return "composition: j ~ U{1..k}, then a sum of j exponential flights";
  }
  /// ℓ = (k + 1)/(2λ) (+∞ where it overflows the doubles).
  [[nodiscard]] double mean_free_path() const override { return quotient_or_infinity(0.5 * (k_ + 1.0), rate_); }
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<ErlangMixture>(*this); }
  [[nodiscard]] std::shared_ptr<const Law> closed_form_scatterer_partner() const override;

 private:
  int k_;
  double rate_;
};

}  // namespace weft::transmittance
