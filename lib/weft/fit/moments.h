#pragma once
/// @file
/// @brief Running mean and variance of window means (Welford), merged pairwise (Chan et al.) in a
/// fixed shard order: the one accumulator of the window statistics (window_stats.h: window_stats, and the
/// models' pass of models.h, which hands its moments to validate).

#include <algorithm>
#include <cstdint>

namespace weft::fit {

struct Moments {
  std::uint64_t n = 0;
  double mean = 0.0;
  double m2 = 0.0;
  void add(double x) {
    ++n;
    const double delta = x - mean;
    mean += delta / static_cast<double>(n);
    m2 += delta * (x - mean);
  }
  void merge(const Moments& o) {
    if (o.n == 0) return;
    if (n == 0) {
      *this = o;
      return;
    }
    const double na = static_cast<double>(n);
    const double nb = static_cast<double>(o.n);
    const double delta = o.mean - mean;
    const double total = na + nb;
    mean += delta * nb / total;
    m2 += o.m2 + delta * delta * na * nb / total;
    n += o.n;
  }
  /// Population variance (≥ 0).
  [[nodiscard]] double variance() const { return n > 0 ? std::max(0.0, m2 / static_cast<double>(n)) : 0.0; }
};

}  // namespace weft::fit
