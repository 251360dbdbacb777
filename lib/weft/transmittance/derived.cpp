#include "weft/transmittance/derived.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <boost/math/quadrature/exp_sinh.hpp>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/roots.hpp>

#include "weft/core/error.h"
#include "weft/core/fp_hold.h"
#include "weft/transmittance/overflow.h"
#include "weft/transmittance/tabulated.h"

namespace weft::transmittance {

namespace {

using Gauss = boost::math::quadrature::gauss<double, 10>;

// The generalised inverse inf{t : f(t) ≤ 0} of a non-increasing f on [lo, hi] with
// f(lo) ≥ 0 ≥ f(hi); returning the bracket's upper end keeps jumps (atoms) exact.
template <typename F>
double solve_decreasing(F f, double lo, double hi) {
  if (f(lo) <= 0.0) return lo;
  std::uintmax_t iterations = 200;
  auto [a, b] = boost::math::tools::toms748_solve(f, lo, hi, boost::math::tools::eps_tolerance<double>(50), iterations);
  // Finish by bisection down to adjacent doubles, so a jump of f lands exactly on its double.
  while (std::nextafter(a, b) < b) {
    const double mid = a + 0.5 * (b - a);
    if (!(mid > a && mid < b)) break;
    (f(mid) > 0.0 ? a : b) = mid;
  }
  return b;
}

// A length scale where T has fallen below `floor` (doubling from `scale`), capped.
template <typename T>
double far_distance(const T& transmittance, double scale, double floor) {
  double t = scale;
  for (int i = 0; i < 200 && transmittance(t) > floor && t < std::numeric_limits<double>::max() / 2; ++i) t *= 2.0;
  return t;
}

// ∫_0^∞ f by Boost's exp-sinh quadrature, with FP exceptions held (fp_hold.h): exp-sinh maps
// the half line onto abscissas x = e^{π/2·sinh(u)} and builds them and their weights level by
// level out to where they overflow to +∞ or the weights underflow, dividing by zero and
// overflowing on the way; it discards those nodes itself (the integrand is only evaluated at
// finite abscissas). The integrands here are weft transmittances, which are trap-clean on their
// own (the property tests run them unheld).
template <typename F>
double integrate_half_line(F f) {
  const HeldFpExceptions hold;
  boost::math::quadrature::exp_sinh<double> integrator;
  return integrator.integrate(f);
}

// ∫_a^b f by adaptive Gauss–Kronrod (15 points, 8 levels, 1e−12 relative), on [0, 1] mapped
// to [a, b]: Boost's recursion compares the error of the unit-interval rule against the
// tolerance times the scaled integral, so on an interval much shorter than 1 it would never
// accept and always refine all 8 levels (2^8 times the work on the grid's short intervals).
template <typename F>
double integrate_interval(F f, double a, double b) {
  using Kronrod = boost::math::quadrature::gauss_kronrod<double, 15>;
  const double width = b - a;
  return width * Kronrod::integrate([&](double x) { return f(a + width * x); }, 0.0, 1.0, 8, 1e-12);
}

// A table's p_Q jumps at its samples (the hazard is constant between them); T_S = p_Q/p_Q(0)
// is only a transmittance if no jump goes up. The grid check below can miss a jump, so for a
// table compare the right and left limits of p_Q at every sample exactly.
void require_non_increasing_table_pdf(const Tabulated& table) {
  const auto& t = table.t_samples();
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double before = table.pdf(std::nextafter(t[i], 0.0));
    const double after = table.pdf(t[i]);
    if (after > before * (1.0 + 1e-9)) {
      fail(
          "reciprocal pair: the table {} as the source law is not convex: p_Q = -dT_Q/dt increases from {} to {} "
          "at sample {} (t = {}), so T_S = p_Q/p_Q(0) would increase; smooth the table or give both laws "
          "(pair mode explicit)",
          table.source(), before, after, i + 1, t[i]);
    }
  }
}

}  // namespace

ScattererFromSource::ScattererFromSource(LawPtr source) : source_(std::move(source)) {
  p0_ = source_->pdf(0.0);
  if (!std::isfinite(p0_)) {
    fail("reciprocal pair: {} as the source law has p_Q(0) = +inf, so T_S = p_Q/p_Q(0) does not exist",
         source_->name());
  }
  if (!(p0_ > 0.0)) {
    fail("reciprocal pair: {} as the source law has p_Q(0) = 0, so T_S = p_Q/p_Q(0) does not exist", source_->name());
  }
  if (!(p0_ <= 1.0 / std::numeric_limits<double>::min() && p0_ >= 1.0 / std::numeric_limits<double>::max())) {
    // l_S = 1/p_Q(0), the scale of T_S, must be a normal double.
    fail("reciprocal pair: {} as the source law has p_Q(0) = {}, so l_S = 1/p_Q(0) is not a normal double",
         source_->name(), p0_);
  }
  if (const auto* table = dynamic_cast<const Tabulated*>(source_.get())) require_non_increasing_table_pdf(*table);
  // p_Q must not increase, or T_S would; check on a grid spanning the law's scale.
  const double scale = std::isfinite(source_->mean_free_path()) ? source_->mean_free_path() : 1.0 / p0_;
  const double far = far_distance([&](double t) { return source_->transmittance(t); }, scale, 1e-12);
  double previous = p0_;
  constexpr int kChecks = 512;
  for (int i = 1; i <= kChecks; ++i) {
    const double t = far * std::pow(1e-6, 1.0 - static_cast<double>(i) / kChecks);
    const double p = source_->pdf(t);
    if (p > previous * (1.0 + 1e-9)) {
      fail("reciprocal pair: p_Q of {} increases near t = {}, so T_S = p_Q/p_Q(0) is not a transmittance",
           source_->name(), t);
    }
    previous = p;
  }
}

double ScattererFromSource::mean_free_path() const {
  // ℓ_S = ∫T_S = ∫p_Q/p_Q(0) = (1 − T_Q(∞))/p_Q(0): a source law with a plateau (rays that never
  // collide, e.g. a table with a flat tail) has ∫p_Q = 1 − T_Q(∞) < 1.
  return (1.0 - source_->transmittance(kInfinity)) / p0_;
}

double ScattererFromSource::transmittance(double t) const { return std::min(1.0, source_->pdf(t) / p0_); }

double ScattererFromSource::log_transmittance(double t) const {
  const double value = transmittance(t);
  if (value > 0.0) return std::log(value);
  // p_Q underflowed: log T_S = log p_Q − log p_Q(0) with log p_Q = log Σ_Q + log T_Q, which stay
  // finite where p_Q = Σ_Q·T_Q underflows. Σ_Q = 0 (a flat T_Q: no more collisions) or T_Q = 0
  // means p_Q is exactly 0.
  const double hazard = source_->hazard(t);
  const double log_tq = source_->log_transmittance(t);
  if (!(hazard > 0.0 && hazard < kInfinity) || !(log_tq > -kInfinity)) return -kInfinity;
  return std::min(0.0, std::log(hazard) + log_tq - std::log(p0_));
}

double ScattererFromSource::pdf(double t) const {
  // p_S = −dT_S/dt by finite differences of g(v) = T_S(v·ℓ_S) in units of ℓ_S = 1/p_Q(0), so the
  // steps stay representable at any scale: 4th-order central differences, one-sided 2nd order
  // near 0 and (backward) near DBL_MAX.
  if (t == kInfinity) return 0.0;
  const double u = product_or_infinity(t, p0_);
  if (u == kInfinity) return 0.0;  // beyond DBL_MAX·ℓ_S: p_Q has long underflowed
  const auto g = [&](double v) { return transmittance(quotient_or_infinity(v, p0_)); };
  const double h = 1e-4 * std::max(u, 1e-2);
  double derivative = 0.0;
  if (u > 0.25 * std::numeric_limits<double>::max()) {
    derivative = (3 * g(u) - 4 * g(u - h) + g(u - 2 * h)) / (2 * h);
  } else if (u > 2.0 * h) {
    derivative = (-g(u + 2 * h) + 8 * g(u + h) - 8 * g(u - h) + g(u - 2 * h)) / (12 * h);
  } else {
    const double hs = 1e-6 + 1e-3 * u;
    derivative = (-3 * g(u) + 4 * g(u + hs) - g(u + 2 * hs)) / (2 * hs);
  }
  return product_or_infinity(std::max(0.0, -derivative), p0_);
}

double ScattererFromSource::hazard(double t) const {
  const double value = transmittance(t);
  if (value == 0.0) return kInfinity;
  return saturating_quotient(pdf(t), value);  // T_S > 0: finite (law.h)
}

double ScattererFromSource::sample(Pcg32& rng) const {
  const double u = 1.0 - rng.uniform();
  if (transmittance(kInfinity) >= u) return kInfinity;
  double hi = 1.0 / p0_;
  while (transmittance(hi) > u) {
    if (hi > 0.5 * std::numeric_limits<double>::max()) return std::numeric_limits<double>::max();  // law.h
    hi *= 2.0;
  }
  return solve_decreasing([&](double t) { return transmittance(t) - u; }, 0.0, hi);
}

SourceFromScatterer::SourceFromScatterer(LawPtr scatterer) : scatterer_(std::move(scatterer)) {
  const double ell = scatterer_->mean_free_path();
  if (!std::isfinite(ell)) {
    fail(
        "reciprocal pair: {} as the scatterer law has an infinite mean free path l_S, so p_Q = T_S/l_S "
        "does not exist",
        scatterer_->name());
  }
  if (!(ell > 0.0)) fail("reciprocal pair: {} has mean free path {}, not > 0", scatterer_->name(), ell);
  if (ell < std::numeric_limits<double>::min()) {
    // 1/l_S, the scale of p_Q and Σ_Q, would overflow.
    fail(
        "reciprocal pair: {} has mean free path {}, below the smallest normal double, so p_Q = T_S/l_S is not "
        "representable",
        scatterer_->name(), ell);
  }
  scale_ = ell;
  // Everything below is in units of ℓ_S (u = t/ℓ_S), so grid, tails and moments stay O(1)
  // whatever the scale of the law (ℓ_S from DBL_MIN to DBL_MAX).
  // Grid: 0, then log-spaced from 1e−6 to where T_S < 1e−18; Gauss on each interval.
  const double far = far_distance([&](double u) { return t_s(u); }, 1.0, 1e-18);
  constexpr int kPoints = 400;
  grid_.push_back(0.0);
  for (int i = 0; i < kPoints; ++i) {
    grid_.push_back(1e-6 * std::pow(far / 1e-6, static_cast<double>(i) / (kPoints - 1)));
  }
  const auto f = [&](double u) { return t_s(u); };
  // u·T_S(u ℓ), as 0 where T_S is 0 (so u = ∞ never meets T_S = 0).
  const auto u_f = [&](double u) {
    const double value = t_s(u);
    return value > 0.0 ? u * value : 0.0;
  };
  tail_.assign(grid_.size(), 0.0);
  const double last = grid_.back();
  tail_.back() = integrate_half_line([&](double v) { return f(last + v); });
  double second = integrate_half_line([&](double v) { return u_f(last + v); });
  // Adaptive Gauss–Kronrod for the table, so kinks of T_S (tabulated laws) cost accuracy
  // only inside the one interval that is evaluated with fixed Gauss later.
  for (std::size_t i = grid_.size() - 1; i-- > 0;) {
    tail_[i] = tail_[i + 1] + integrate_interval(f, grid_[i], grid_[i + 1]);
    second += integrate_interval(u_f, grid_[i], grid_[i + 1]);
  }
  ell_u_ = tail_[0];
  if (!(std::fabs(ell_u_ - 1.0) <= 1e-6)) {
    fail("reciprocal pair: integrating T_S of {} gives {} but its mean free path is {}", scatterer_->name(),
         ell_u_ * ell, ell);
  }
  // ℓ_Q = ∫T_Q = ∫ t p_Q(t) dt = ∫ t T_S / ℓ_S = ℓ_S ∫ u T_S(uℓ_S) du / ∫ T_S(uℓ_S) du.
  mean_free_path_ = std::isfinite(second) ? product_or_infinity(scale_, second / ell_u_) : kInfinity;
}

double SourceFromScatterer::t_s(double u) const { return scatterer_->transmittance(product_or_infinity(u, scale_)); }

double SourceFromScatterer::integral_to_infinity(double u) const {
  if (u <= 0.0) return ell_u_;
  if (u == kInfinity) return 0.0;
  const auto f = [&](double v) { return t_s(v); };
  if (u >= grid_.back()) return integrate_half_line([&](double v) { return f(u + v); });
  const auto it = std::upper_bound(grid_.begin(), grid_.end(), u);
  const auto j = static_cast<std::size_t>(it - grid_.begin());
  return tail_[j] + Gauss::integrate(f, u, grid_[j]);
}

double SourceFromScatterer::transmittance(double t) const {
  return std::clamp(integral_to_infinity(quotient_or_infinity(t, scale_)) / ell_u_, 0.0, 1.0);
}

double SourceFromScatterer::log_transmittance(double t) const {
  const double value = transmittance(t);
  return value > 0.0 ? std::log(value) : -kInfinity;
}

double SourceFromScatterer::pdf(double t) const {
  return quotient_or_infinity(scatterer_->transmittance(t) / ell_u_, scale_);
}

double SourceFromScatterer::hazard(double t) const {
  const double value = integral_to_infinity(quotient_or_infinity(t, scale_));
  if (value == 0.0) return t == kInfinity ? scatterer_->hazard(t) : kInfinity;
  return saturating_quotient(quotient_or_infinity(scatterer_->transmittance(t), value), scale_);  // T_Q > 0
}

double SourceFromScatterer::sample(Pcg32& rng) const {
  return saturating_product(sample_scaled(rng), scale_);  // DBL_MAX beyond the largest double (law.h)
}

double SourceFromScatterer::sample_scaled(Pcg32& rng) const {
  const double target = (1.0 - rng.uniform()) * ell_u_;  // ∫_u^∞ T_S = ξ·ℓ_S, in units of ℓ_S
  // tail_ decreases; find the first grid point whose tail is below the target.
  const auto it =
      std::upper_bound(tail_.begin(), tail_.end(), target, [](double value, double tail) { return tail < value; });
  const auto f = [&](double u) { return integral_to_infinity(u) - target; };
  if (it == tail_.end()) {
    double lo = grid_.back();
    double hi = 2.0 * lo;
    while (integral_to_infinity(hi) > target) {
      lo = hi;
      hi *= 2.0;
      if (product_or_infinity(hi, scale_) == kInfinity) return hi;  // beyond DBL_MAX in length units
    }
    return solve_decreasing(f, lo, hi);
  }
  const auto j = static_cast<std::size_t>(it - tail_.begin());
  if (j == 0) return 0.0;
  // Safeguarded Newton inside [u_{j−1}, u_j]: d/du ∫_u^∞ T_S = −T_S(uℓ) is known exactly, so a
  // few steps reach double precision; fall back on bisection when a step leaves the bracket.
  double lo = grid_[j - 1];
  double hi = grid_[j];
  double u = lo + (hi - lo) * (tail_[j - 1] - target) / (tail_[j - 1] - tail_[j]);
  for (int step = 0; step < 60; ++step) {
    const double value = f(u);
    if (value > 0.0) {
      lo = u;
    } else {
      hi = u;
    }
    const double slope = t_s(u);
    double next = slope > 0.0 ? u + value / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - u) <= 1e-14 * next || hi - lo <= 1e-14 * hi) return next;
    u = next;
  }
  return u;
}

}  // namespace weft::transmittance
