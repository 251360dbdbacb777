#pragma once
/// @file
/// @brief Free paths of one quantity in one realization, binned (Tally), and their means with
/// standard errors over realizations (supplement S.11.2).

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "data_gen/media2d/simulation.h"

namespace weft::media2d {

// Free paths of one quantity in one realization, binned so that T, p and the exact bin
// integrals of T can be recovered: ∫_bin T = Δ·T(t_{k+1}) + Σ_{f in bin}(f − t_k)/M.
struct Tally {
  std::vector<std::uint32_t> counts;
  std::vector<double> offsets;
  std::uint32_t survivors = 0;
  double truncated_sum = 0.0;  // Σ min(f, t_max)
  std::uint32_t n = 0;

  explicit Tally(std::size_t bins) : counts(bins, 0), offsets(bins, 0.0) {}
  void add(double f, double t_max, double width) {
    ++n;
    if (!(f < t_max)) {
      ++survivors;
      truncated_sum += t_max;
      return;
    }
    const auto k = std::min(counts.size() - 1, static_cast<std::size_t>(f / width));
    ++counts[k];
    offsets[k] += f - width * static_cast<double>(k);
    truncated_sum += f;
  }
  // T at the edges t_0 … t_bins.
  [[nodiscard]] std::vector<double> transmittance() const {
    std::vector<double> t(counts.size() + 1);
    double above = survivors;
    t[counts.size()] = above / n;
    for (std::size_t k = counts.size(); k-- > 0;) {
      above += counts[k];
      t[k] = above / n;
    }
    return t;
  }
  [[nodiscard]] std::vector<double> bin_probability() const {
    std::vector<double> p(counts.size());
    for (std::size_t k = 0; k < counts.size(); ++k) p[k] = static_cast<double>(counts[k]) / n;
    return p;
  }
  [[nodiscard]] std::vector<double> bin_integral(double width) const {
    const std::vector<double> t = transmittance();
    std::vector<double> integral(counts.size());
    for (std::size_t k = 0; k < counts.size(); ++k) integral[k] = width * t[k + 1] + offsets[k] / n;
    return integral;
  }
};

/// Mean and standard error over realizations of per-realization vectors (one realization: the
/// binomial error of a fraction of `samples` rays).
[[nodiscard]] Curve mean_curve(const std::vector<std::vector<double>>& rows, std::size_t samples);
/// T at the bin edges, over realizations.
[[nodiscard]] Curve transmittance_curve(const std::vector<const Tally*>& tallies, std::size_t samples);
/// The free-path pdf at the bin centres, over realizations.
[[nodiscard]] Curve pdf_curve(const std::vector<const Tally*>& tallies, std::size_t samples, double width);
/// ∫₀^{t_max} T (the mean truncated free path) and its standard error, over realizations.
[[nodiscard]] std::pair<double, double> mean_truncated(const std::vector<const Tally*>& tallies, std::size_t samples);

}  // namespace weft::media2d
