#pragma once
// Kolmogorov–Smirnov test of a sampler against its exact CDF, shared by the sampler tests.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "weft/core/rng.h"
#include "weft/transmittance/law.h"

namespace weft::transmittance::testing {

inline constexpr int kSamples = 100000;
/// Significance of each KS test: a correct sampler fails one test with probability 1e−4.
inline constexpr double kSignificance = 1e-4;

/// Asymptotic Kolmogorov critical value: P(√n·D > c) ≈ 2e^{−2c²} = significance.
inline double ks_critical_value(int n, double significance = kSignificance) {
  return std::sqrt(-0.5 * std::log(0.5 * significance)) / std::sqrt(static_cast<double>(n));
}

/// D = sup |F_n − F|. Samples are doubles, so a sample v stands for the true values that round
/// to it: the empirical step at v is compared with F just above and just below v. This makes
/// atoms that rounding creates (0 for k ≪ 1, DBL_MAX or +∞ for heavy tails) legitimate, not failures.
/// Subnormal samples carry no relative precision (nor does t/θ at such t), so everything
/// below DBL_MIN is one bin [0, DBL_MIN).
inline double ks_statistic(std::vector<double> samples, const std::function<double(double)>& cdf) {
  constexpr double kSmallest = std::numeric_limits<double>::min();
  for (auto& x : samples) {
    if (x < kSmallest) x = 0.0;
  }
  std::sort(samples.begin(), samples.end());
  const auto n = static_cast<double>(samples.size());
  const auto cdf_at = [&](double t) {
    if (t < 0.0) return 0.0;
    if (t == std::numeric_limits<double>::infinity()) return 1.0;
    return cdf(t);
  };
  double d = 0.0;
  std::size_t i = 0;
  while (i < samples.size()) {
    const double v = samples[i];
    std::size_t j = i;
    while (j < samples.size() && samples[j] == v) ++j;
    const double below = cdf_at(std::nextafter(v, -std::numeric_limits<double>::infinity()));
    // Draws beyond the largest double saturate at DBL_MAX (law.h): F just above it is 1 (and
    // nextafter(DBL_MAX, +inf) would raise FE_OVERFLOW).
    const double above =
        v == std::numeric_limits<double>::max()
            ? 1.0
            : cdf_at(v == 0.0 ? kSmallest : std::nextafter(v, std::numeric_limits<double>::infinity()));
    d = std::max({d, static_cast<double>(j) / n - above, below - static_cast<double>(i) / n});
    i = j;
  }
  return d;
}

inline std::vector<double> draw(const std::function<double(Pcg32&)>& sampler, std::uint64_t seed, int n = kSamples) {
  Pcg32 rng = stream_for(seed, 0);
  std::vector<double> out(static_cast<std::size_t>(n));
  for (auto& x : out) x = sampler(rng);
  return out;
}

/// The law's own CDF, 1 − T(t).
inline std::function<double(double)> law_cdf(const Law& law) {
  return [&law](double t) { return 1.0 - law.transmittance(t); };
}

}  // namespace weft::transmittance::testing
