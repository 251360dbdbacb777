#include "weft/transmittance/derived.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <boost/math/quadrature/exp_sinh.hpp>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/roots.hpp>

#include "weft/core/error.h"

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
double far_distance(const T& law, double scale, double floor) {
  double t = scale;
  for (int i = 0; i < 200 && law.transmittance(t) > floor; ++i) t *= 2.0;
  return t;
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
  // p_Q must not increase, or T_S would; check on a grid spanning the law's scale.
  const double scale = std::isfinite(source_->mean_free_path()) ? source_->mean_free_path() : 1.0 / p0_;
  const double far = far_distance(*source_, scale, 1e-12);
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

double ScattererFromSource::transmittance(double t) const { return std::min(1.0, source_->pdf(t) / p0_); }

double ScattererFromSource::log_transmittance(double t) const {
  const double value = transmittance(t);
  if (value > 0.0) return std::log(value);
  // p_Q underflowed: −log T_S ≥ −log T_Q − log(ℓ_S Σ…); fall back on log p = log Σ + log T.
  return std::log(source_->hazard(t)) + source_->log_transmittance(t) - std::log(p0_);
}

double ScattererFromSource::pdf(double t) const {
  // p_S = −p_Q'(t)/p_Q(0): 4th-order central differences, one-sided 2nd order near 0.
  const double h = 1e-4 * std::max(t, 1e-2 / p0_);
  const auto p = [&](double s) { return source_->pdf(s); };
  double derivative = 0.0;
  if (t > 2.0 * h) {
    derivative = (-p(t + 2 * h) + 8 * p(t + h) - 8 * p(t - h) + p(t - 2 * h)) / (12 * h);
  } else {
    const double hs = 1e-6 / p0_ + 1e-3 * t;
    derivative = (-3 * p(t) + 4 * p(t + hs) - p(t + 2 * hs)) / (2 * hs);
  }
  return std::max(0.0, -derivative / p0_);
}

double ScattererFromSource::hazard(double t) const {
  const double value = transmittance(t);
  if (value == 0.0) return kInfinity;
  return pdf(t) / value;
}

double ScattererFromSource::sample(Pcg32& rng) const {
  const double u = 1.0 - rng.uniform();
  if (transmittance(kInfinity) >= u) return kInfinity;
  double hi = 1.0 / p0_;
  while (transmittance(hi) > u) {
    hi *= 2.0;
    if (!std::isfinite(hi)) return kInfinity;
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
  // Grid: 0, then log-spaced from 1e−6 ℓ_S to where T_S < 1e−18; Gauss on each interval.
  const double far = far_distance(*scatterer_, ell, 1e-18);
  constexpr int kPoints = 400;
  grid_.push_back(0.0);
  for (int i = 0; i < kPoints; ++i) {
    grid_.push_back(1e-6 * ell * std::pow(far / (1e-6 * ell), static_cast<double>(i) / (kPoints - 1)));
  }
  const auto t_s = [&](double s) { return scatterer_->transmittance(s); };
  const auto t_s_times_s = [&](double s) { return s * scatterer_->transmittance(s); };
  tail_.assign(grid_.size(), 0.0);
  boost::math::quadrature::exp_sinh<double> tail_integrator;
  const double last = grid_.back();
  tail_.back() = tail_integrator.integrate([&](double s) { return t_s(last + s); });
  double second = tail_integrator.integrate([&](double s) { return t_s_times_s(last + s); });
  // Adaptive Gauss–Kronrod for the table, so kinks of T_S (tabulated laws) cost accuracy
  // only inside the one interval that is evaluated with fixed Gauss later.
  using Kronrod = boost::math::quadrature::gauss_kronrod<double, 15>;
  for (std::size_t i = grid_.size() - 1; i-- > 0;) {
    tail_[i] = tail_[i + 1] + Kronrod::integrate(t_s, grid_[i], grid_[i + 1], 8, 1e-12);
    second += Kronrod::integrate(t_s_times_s, grid_[i], grid_[i + 1], 8, 1e-12);
  }
  ell_s_ = tail_[0];
  if (std::fabs(ell_s_ / ell - 1.0) > 1e-6) {
    fail("reciprocal pair: integrating T_S of {} gives {} but its mean free path is {}", scatterer_->name(), ell_s_,
         ell);
  }
  // ℓ_Q = ∫T_Q = ∫ t p_Q(t) dt = ∫ t T_S / ℓ_S.
  mean_free_path_ = std::isfinite(second) ? second / ell_s_ : kInfinity;
}

double SourceFromScatterer::integral_to_infinity(double t) const {
  if (t <= 0.0) return ell_s_;
  if (t == kInfinity) return 0.0;
  const auto t_s = [&](double s) { return scatterer_->transmittance(s); };
  if (t >= grid_.back()) {
    boost::math::quadrature::exp_sinh<double> integrator;
    return integrator.integrate([&](double s) { return t_s(t + s); });
  }
  const auto it = std::upper_bound(grid_.begin(), grid_.end(), t);
  const auto j = static_cast<std::size_t>(it - grid_.begin());
  return tail_[j] + Gauss::integrate(t_s, t, grid_[j]);
}

double SourceFromScatterer::transmittance(double t) const {
  return std::clamp(integral_to_infinity(t) / ell_s_, 0.0, 1.0);
}

double SourceFromScatterer::log_transmittance(double t) const { return std::log(transmittance(t)); }

double SourceFromScatterer::pdf(double t) const { return scatterer_->transmittance(t) / ell_s_; }

double SourceFromScatterer::hazard(double t) const {
  const double value = integral_to_infinity(t);
  if (value == 0.0) return t == kInfinity ? scatterer_->hazard(t) : kInfinity;
  return scatterer_->transmittance(t) / value;
}

double SourceFromScatterer::sample(Pcg32& rng) const {
  const double target = (1.0 - rng.uniform()) * ell_s_;  // ∫_t^∞ T_S = u·ℓ_S
  // tail_ decreases; find the first grid point whose tail is below the target.
  const auto it =
      std::upper_bound(tail_.begin(), tail_.end(), target, [](double value, double tail) { return tail < value; });
  const auto f = [&](double t) { return integral_to_infinity(t) - target; };
  if (it == tail_.end()) {
    double lo = grid_.back();
    double hi = 2.0 * lo;
    while (integral_to_infinity(hi) > target) {
      lo = hi;
      hi *= 2.0;
      if (!std::isfinite(hi)) return kInfinity;
    }
    return solve_decreasing(f, lo, hi);
  }
  const auto j = static_cast<std::size_t>(it - tail_.begin());
  if (j == 0) return 0.0;
  // Safeguarded Newton inside [t_{j−1}, t_j]: d/dt ∫_t^∞ T_S = −T_S(t) is known exactly, so a
  // few steps reach double precision; fall back on bisection when a step leaves the bracket.
  double lo = grid_[j - 1];
  double hi = grid_[j];
  double t = lo + (hi - lo) * (tail_[j - 1] - target) / (tail_[j - 1] - tail_[j]);
  for (int step = 0; step < 60; ++step) {
    const double value = f(t);
    if (value > 0.0) {
      lo = t;
    } else {
      hi = t;
    }
    const double slope = scatterer_->transmittance(t);
    double next = slope > 0.0 ? t + value / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - t) <= 1e-14 * next || hi - lo <= 1e-14 * hi) return next;
    t = next;
  }
  return t;
}

}  // namespace weft::transmittance
