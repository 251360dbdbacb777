// The Gamma(k, 1) quantiles (transmittance/gamma_path.h): Boost's inverse where it converges, the
// Cornish–Fisher expansion above k = 10⁸, checked against Boost's inverse where both exist and
// against the forward incomplete gamma function where only the expansion does.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <boost/math/special_functions/gamma.hpp>

#include "weft/transmittance/gamma_path.h"

namespace weft::transmittance {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Lower-tail probabilities from 10⁻¹² to 1 − 10⁻⁶ (z from −7 to 4.8).
constexpr double kProbabilities[] = {1e-12, 1e-6, 1.0 / 64, 0.3, 0.5, 0.7, 63.0 / 64, 1 - 1e-6};

TEST(GammaQuantile, CornishFisherIsBoostsInverseWithinRoundingFromTheBranchOn) {
  // The expansion's remainder is O(k^{−5/2}) · poly(z): about 10⁻²⁰ at k = 10⁸, so the two agree
  // to the rounding of the iteration (a few ulp); at k = 10⁴ the remainder is visible, which is
  // why the branch starts at 10⁸.
  for (double k : {1e8, 1.5e8, 1e9, 1e10}) {
    for (double p : kProbabilities) {
      const double z = -std::sqrt(2.0) * boost::math::erfc_inv(2.0 * p);
      const double boost_x = boost::math::gamma_p_inv(k, p) / k;
      EXPECT_NEAR(gamma_quantile_cornish_fisher(k, z), boost_x, 4 * kEps * boost_x) << "k " << k << " p " << p;
    }
  }
  double worst = 0.0;
  for (double p : kProbabilities) {
    const double z = -std::sqrt(2.0) * boost::math::erfc_inv(2.0 * p);
    const double boost_x = boost::math::gamma_p_inv(1e4, p) / 1e4;
    worst = std::max(worst, std::abs(gamma_quantile_cornish_fisher(1e4, z) / boost_x - 1.0));
  }
  EXPECT_GT(worst, 1e3 * kEps) << "the expansion's remainder should show at k = 10⁴";
}

TEST(GammaQuantile, BeyondBoostsReachTheQuantileIsOrderedAndConsistentInBothTails) {
  // Boost's gamma_p_inv and its forward P(k, x) both throw (series iteration limit) from about
  // k = 2·10¹⁰ on, so there is nothing of Boost's to compare with there; the expansion was
  // checked against Boost up to 10¹⁰ above, and its remainder only shrinks with k. Here: it
  // answers, increases with p, stays within z/√k ± 1/k of 1 (the first two terms), and the
  // upper-tail form Q⁻¹(k, q) is P⁻¹(k, 1 − q) to rounding where 1 − q is exact.
  for (double k : {3e10, 1e12, 1e15, 1e20}) {
    double previous = 0.0;
    for (double p : kProbabilities) {
      double x = 0.0;
      ASSERT_NO_THROW(x = gamma_p_inverse(k, p)) << "k " << k << " p " << p;
      ASSERT_TRUE(std::isfinite(x) && x > previous) << "k " << k << " p " << p << " x " << x;
      previous = x;
      const double z = -std::sqrt(2.0) * boost::math::erfc_inv(2.0 * p);
      EXPECT_NEAR(x / k, 1.0 + z / std::sqrt(k), 20.0 / k + 2 * kEps) << "k " << k << " p " << p;
      if (p >= 1.0 / 64) {
        EXPECT_NEAR(gamma_q_inverse(k, 1.0 - p), x, 4 * kEps * x) << "k " << k << " p " << p;
      }
    }
  }
}

TEST(GammaQuantile, BelowTheBranchItIsBoostsInverse) {
  // In double precision, as the laws evaluate it (gamma_path.cpp's policy).
  using Double = boost::math::policies::policy<boost::math::policies::promote_double<false>>;
  for (double k : {1e-3, 0.5, 3.0, 1e4, 1e8}) {
    for (double p : kProbabilities) {
      EXPECT_EQ(gamma_p_inverse(k, p), boost::math::gamma_p_inv(k, p, Double())) << "k " << k << " p " << p;
    }
  }
}

}  // namespace
}  // namespace weft::transmittance
