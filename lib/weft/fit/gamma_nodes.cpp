// The two-scale prediction's quadrature nodes from a shared table and one Halley step
// (fit/gamma_nodes.h).
#include "weft/fit/gamma_nodes.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <boost/math/special_functions/gamma.hpp>
#include <boost/math/tools/roots.hpp>

#include "weft/core/parallel.h"
#include "weft/transmittance/gamma_path.h"

namespace weft::fit::detail {
namespace {

// In double precision (Boost's default promotes to long double, 5x the cost for the last bit of
// a node: docs/benchmarks.md "Validate: predictions against the truth").
using Double = boost::math::policies::policy<boost::math::policies::promote_double<false>>;

constexpr double kPerUnit = 16.0;  // lattice points per unit of ln α
// Below α = 1/8 gamma_p_inv may ask for more digits (a steep P): left to it. Above 10⁸ (a nearly
// uniform column) the nodes are 1 to within 10⁻⁴ and the quantile's Cornish–Fisher expansion is
// exact to rounding (transmittance/gamma_path.h): no table either.
constexpr double kMinShape = 0.125;
constexpr double kMaxShape = transmittance::kLargeGammaShape;
// The six lattice points around α: offsets −2 … 3 from floor(ln α · 16).
constexpr int kBefore = 2;
constexpr int kPoints = 6;

double probability(int j) { return (j + 0.5) / kNodes; }

bool in_table(double shape) { return shape >= kMinShape && shape <= kMaxShape; }

std::int64_t floor_point(double shape) { return static_cast<std::int64_t>(std::floor(std::log(shape) * kPerUnit)); }

double shape_at(std::int64_t point) { return std::exp(static_cast<double>(point) / kPerUnit); }

}  // namespace

double exact_gamma_node(double shape, int j) { return transmittance::gamma_p_inverse(shape, probability(j)) / shape; }

GammaNodes::GammaNodes(const std::vector<double>& shapes) {
  for (double a : shapes) {
    if (!in_table(a)) continue;
    const std::int64_t i0 = floor_point(a);
    for (int m = 0; m < kPoints; ++m) lattice_.push_back(i0 - kBefore + m);
  }
  std::sort(lattice_.begin(), lattice_.end());
  lattice_.erase(std::unique(lattice_.begin(), lattice_.end()), lattice_.end());
  log_node_.assign(lattice_.size() * kNodes, 0.0);
  parallel_units(lattice_.size(), [&](std::size_t e) {
    const double a = shape_at(lattice_[e]);
    for (int j = 0; j < kNodes; ++j)
      log_node_[e * kNodes + static_cast<std::size_t>(j)] = std::log(exact_gamma_node(a, j));
  });
}

void GammaNodes::nodes(double shape, double* out) const {
  if (!in_table(shape)) {
    for (int j = 0; j < kNodes; ++j) out[j] = exact_gamma_node(shape, j);
    return;
  }
  const double u = std::log(shape) * kPerUnit;
  const std::int64_t i0 = floor_point(shape);
  const auto first = std::lower_bound(lattice_.begin(), lattice_.end(), i0 - kBefore);
  const auto e0 = static_cast<std::size_t>(first - lattice_.begin());
  if (first == lattice_.end() || e0 + kPoints > lattice_.size() ||
      lattice_[e0 + kPoints - 1] != i0 - kBefore + kPoints - 1) {
    for (int j = 0; j < kNodes; ++j) out[j] = exact_gamma_node(shape, j);  // a shape the table was not built for
    return;
  }
  // Lagrange weights of the six points at t = u − i0 (points at offsets −2 … 3).
  const double t = u - static_cast<double>(i0);
  double weight[kPoints];
  for (int m = 0; m < kPoints; ++m) {
    double w = 1.0;
    for (int q = 0; q < kPoints; ++q) {
      if (q != m) w *= (t - (q - kBefore)) / static_cast<double>(m - q);
    }
    weight[m] = w;
  }
  // gamma_p_inv's iteration (its digits, bounds and step), from the interpolated guess.
  constexpr int kDigits = std::numeric_limits<double>::digits / 2 - 1;
  const double lower = std::numeric_limits<double>::min();
  const double upper = std::numeric_limits<double>::max();
  for (int j = 0; j < kNodes; ++j) {
    double g = 0.0;
    for (int m = 0; m < kPoints; ++m)
      g += weight[m] * log_node_[(e0 + static_cast<std::size_t>(m)) * kNodes + static_cast<std::size_t>(j)];
    const double guess = shape * std::exp(g);
    std::uintmax_t iterations = 50;
    const double x = boost::math::tools::halley_iterate(
        boost::math::detail::gamma_p_inverse_func<double, Double>(shape, probability(j), false), guess, lower, upper,
        kDigits, iterations);
    // Not converged, or on the lower bound (what gamma_p_inv reports as an underflow): its own way.
    out[j] = iterations < 50 && x > lower && std::isfinite(x) ? x / shape : exact_gamma_node(shape, j);
  }
}

}  // namespace weft::fit::detail
