#include "data_gen/media2d/tally.h"

#include <algorithm>
#include <cmath>

namespace weft::media2d {

Curve mean_curve(const std::vector<std::vector<double>>& rows, std::size_t samples) {
  Curve c;
  const std::size_t m = rows.front().size();
  const auto r = static_cast<double>(rows.size());
  c.value.assign(m, 0.0);
  c.stderr_.assign(m, 0.0);
  for (const auto& row : rows) {
    for (std::size_t k = 0; k < m; ++k) c.value[k] += row[k];
  }
  for (auto& v : c.value) v /= r;
  if (rows.size() >= 2) {
    for (const auto& row : rows) {
      for (std::size_t k = 0; k < m; ++k) c.stderr_[k] += (row[k] - c.value[k]) * (row[k] - c.value[k]);
    }
    for (auto& v : c.stderr_) v = std::sqrt(v / (r - 1.0) / r);
  } else {
    // One realization: the binomial error of a fraction of `samples` rays.
    for (std::size_t k = 0; k < m; ++k) {
      const double p = std::clamp(c.value[k], 0.0, 1.0);
      c.stderr_[k] = std::sqrt(p * (1.0 - p) / static_cast<double>(samples));
    }
  }
  return c;
}

Curve transmittance_curve(const std::vector<const Tally*>& tallies, std::size_t samples) {
  std::vector<std::vector<double>> rows;
  rows.reserve(tallies.size());
  for (const Tally* t : tallies) rows.push_back(t->transmittance());
  return mean_curve(rows, samples);
}

Curve pdf_curve(const std::vector<const Tally*>& tallies, std::size_t samples, double width) {
  std::vector<std::vector<double>> rows;
  rows.reserve(tallies.size());
  for (const Tally* t : tallies) rows.push_back(t->bin_probability());
  Curve c = mean_curve(rows, samples);
  for (auto& v : c.value) v /= width;
  for (auto& v : c.stderr_) v /= width;
  return c;
}

std::pair<double, double> mean_truncated(const std::vector<const Tally*>& tallies, std::size_t samples) {
  std::vector<std::vector<double>> rows;
  rows.reserve(tallies.size());
  for (const Tally* t : tallies) rows.push_back({t->truncated_sum / t->n});
  const Curve c = mean_curve(rows, samples);
  double se = c.stderr_[0];
  if (tallies.size() < 2) se = 0.0;
  return {c.value[0], se};
}

}  // namespace weft::media2d
