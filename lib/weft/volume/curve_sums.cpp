#include "weft/volume/curve_sums.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "weft/core/error.h"

namespace weft::volume {

void CurveSums::add_log(const std::vector<double>& log_t) {
  for (std::size_t k = 0; k < log_t.size(); ++k) {
    const double e = std::exp(log_t[k]);
    s1[k] += e;
    s2[k] += e * e;
  }
  ++n;
}

void CurveSums::merge(const CurveSums& other) {
  if (other.n == 0) return;
  if (s1.size() != other.s1.size()) fail("curve sums: {} depths against {}", s1.size(), other.s1.size());
  for (std::size_t k = 0; k < s1.size(); ++k) {
    s1[k] += other.s1[k];
    s2[k] += other.s2[k];
  }
  n += other.n;
}

TransmittanceCurve curve_of_sums(const std::vector<CurveSums>& parts, const std::vector<double>& depths,
                                 const std::array<double, 3>& direction, std::string method, const std::string& what) {
  const std::size_t K = depths.size();
  CurveSums total(K);
  for (const CurveSums& p : parts) total.merge(p);
  if (total.n == 0) fail("{}: no ray entered the box", what);
  TransmittanceCurve c;
  c.depth = depths;
  c.direction = direction;
  c.rays = total.n;
  c.distinct_rays = total.n;
  c.method = std::move(method);
  c.log_t.assign(K, 0.0);
  c.rel_stderr.assign(K, 0.0);
  const auto n = static_cast<double>(total.n);
  for (std::size_t k = 0; k < K; ++k) {
    if (!(total.s1[k] > 0.0)) {
      c.log_t[k] = -std::numeric_limits<double>::infinity();
      continue;
    }
    c.log_t[k] = std::log(total.s1[k] / n);
    // The sample variance of T_i over the mean², over n − 1: the mean's relative standard error².
    const double rel_var = std::max(0.0, n * total.s2[k] / (total.s1[k] * total.s1[k]) - 1.0);
    c.rel_stderr[k] = total.n > 1 ? std::sqrt(rel_var / (n - 1.0)) : 0.0;
  }
  return c;
}

}  // namespace weft::volume
