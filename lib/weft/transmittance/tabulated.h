#pragma once
/// @file
/// @brief A transmittance curve given as samples (t_i, T_i), e.g. measured in a voxel grid.
///
/// Between samples, log T is linear (the hazard is constant on each interval), so T stays
/// positive and monotone and sampling inverts exactly. An interval that ends at T = 0 is linear
/// in T instead (log T would be −∞ on all of it). Beyond the last sample the last interval's
/// hazard continues (an exponential tail); if that hazard is 0, the remaining T_N is the
/// probability of never colliding (sampling returns +∞, ℓ = +∞).

#include <string>

#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// @brief Piecewise log-linear transmittance through given samples.
class Tabulated final : public Law {
 public:
  /// t strictly increasing from t_0 = 0, T_0 = 1, T in [0, 1], non-increasing, all finite,
  /// at least two samples; `source` names the input in errors (a file name or "table").
  Tabulated(std::vector<double> t, std::vector<double> transmittance, std::string source = "table");

  /// Reads a CSV with columns t,T (an optional header line; blank lines and # comments skipped).
  static Tabulated from_csv(const std::string& path);

  [[nodiscard]] const std::vector<double>& t_samples() const { return t_; }
  [[nodiscard]] const std::vector<double>& transmittance_samples() const { return value_; }
  [[nodiscard]] const std::string& source() const { return source_; }

  [[nodiscard]] std::string name() const override { return "tabulated"; }
  [[nodiscard]] std::vector<Parameter> parameters() const override {
    return {{"samples", static_cast<double>(t_.size())}};
  }
  [[nodiscard]] double transmittance(double t) const override;
  [[nodiscard]] double log_transmittance(double t) const override;
  [[nodiscard]] double pdf(double t) const override;
  [[nodiscard]] double hazard(double t) const override;
  /// Exact inversion of the interpolated T (binary search on log T, then a log-linear solve).
  [[nodiscard]] double sample(Pcg32& rng) const override;
  [[nodiscard]] std::string sampling_method() const override { return "inversion of the log-linear T"; }
  [[nodiscard]] double mean_free_path() const override;
  [[nodiscard]] std::unique_ptr<Law> clone() const override { return std::make_unique<Tabulated>(*this); }

 private:
  /// Index i of the interval [t_i, t_{i+1}) holding t; size()−1 for the tail.
  [[nodiscard]] std::size_t interval(double t) const;
  std::vector<double> t_;
  std::vector<double> value_;
  std::vector<double> log_value_;
  std::vector<double> hazard_;  ///< per interval (and the tail = last interval's); NaN for linear-to-0
  std::string source_;
};

}  // namespace weft::transmittance
