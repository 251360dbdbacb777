#include "data_gen/media2d/reciprocity.h"

#include <cmath>

namespace weft::media2d {

Reciprocity check_reciprocity(const std::vector<const Tally*>& source, const std::vector<const Tally*>& scatterer,
                              std::size_t samples, const SimulationResult& result) {
  Reciprocity rec;
  const double width = result.edges[1] - result.edges[0];
  const auto [ell, ell_se] = mean_truncated(scatterer, samples);
  rec.ell_s = ell;
  rec.ell_s_stderr = ell_se;
  rec.tail_t_s = transmittance_curve(scatterer, samples).value.back();
  std::vector<std::vector<double>> p_rows;
  std::vector<std::vector<double>> i_rows;
  for (std::size_t j = 0; j < source.size(); ++j) {
    p_rows.push_back(source[j]->bin_probability());
    i_rows.push_back(scatterer[j]->bin_integral(width));
  }
  const Curve p_mean = mean_curve(p_rows, samples);
  const Curve i_mean = mean_curve(i_rows, samples);
  // Per realization D_k = P_Q,k − c·I_S,k keeps the correlation of both estimates within a medium.
  auto differences = [&](double c) {
    std::vector<std::vector<double>> rows;
    for (std::size_t j = 0; j < p_rows.size(); ++j) {
      std::vector<double> d(p_rows[j].size());
      for (std::size_t k = 0; k < d.size(); ++k) d[k] = p_rows[j][k] - c * i_rows[j][k];
      rows.push_back(std::move(d));
    }
    return mean_curve(rows, samples);
  };
  // c = 1/ℓ_S by weighted least squares, so a tail of T_S beyond t_max (which the truncated
  // integral misses) does not masquerade as a violation; two passes settle the weights.
  // Bins where the source free paths counted fewer than 20 times over all realizations are left
  // out: there the spread over realizations is not a Gaussian error.
  const double total = static_cast<double>(samples * source.size());
  auto usable = [&](std::size_t k, const Curve& d) { return d.stderr_[k] > 0.0 && p_mean.value[k] * total >= 20.0; };
  double c = ell > 0.0 ? 1.0 / ell : 1.0;
  double c_se = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    const Curve d = differences(c);
    double num = 0.0;
    double den = 0.0;
    for (std::size_t k = 0; k < d.value.size(); ++k) {
      if (!usable(k, d)) continue;
      const double w = 1.0 / (d.stderr_[k] * d.stderr_[k]);
      num += w * p_mean.value[k] * i_mean.value[k];
      den += w * i_mean.value[k] * i_mean.value[k];
    }
    if (den > 0.0) {
      c = num / den;
      c_se = 1.0 / std::sqrt(den);
    }
  }
  rec.ell_s_fit = 1.0 / c;
  rec.ell_s_fit_stderr = c_se / (c * c);
  const Curve diff = differences(c);
  rec.residual = diff.value;
  rec.residual_stderr = diff.stderr_;
  std::size_t used = 0;
  for (std::size_t k = 0; k < diff.value.size(); ++k) {
    if (!usable(k, diff)) continue;
    const double z = diff.value[k] / diff.stderr_[k];
    rec.chi2 += z * z;
    ++used;
    if (std::abs(z) > rec.max_abs_z) {
      rec.max_abs_z = std::abs(z);
      rec.max_abs_z_t = result.centres[k];
    }
  }
  rec.dof = used > 1 ? used - 1 : 0;
  return rec;
}

}  // namespace weft::media2d
