// Concentration moments → gamma shape and rate (transmittance/shape_rate.h, Eq. 19) at the
// extremes where the naive C̄²/Var C overflows or divides by zero.
#include "weft/transmittance/shape_rate.h"

#include <gtest/gtest.h>

#include <cfenv>
#include <cmath>
#include <limits>

namespace weft::transmittance {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(GammaShapeRate, OrdinaryMomentsGiveTheTextbookValues) {
  const ShapeRate s = gamma_shape_rate(2.0, 0.5);
  EXPECT_DOUBLE_EQ(s.beta, 4.0);
  EXPECT_DOUBLE_EQ(s.alpha, 8.0);
}

TEST(GammaShapeRate, ZeroVarianceIsExactlyTheExponentialLimit) {
  for (const double mean : {0.0, 1e-300, 1.0, 1e300}) {
    const ShapeRate s = gamma_shape_rate(mean, 0.0);
    EXPECT_EQ(s.alpha, kInf) << mean;
    EXPECT_EQ(s.beta, kInf) << mean;
  }
}

TEST(GammaShapeRate, SubnormalVarianceOverflowsToInfinityWithoutRaising) {
  const double var = std::numeric_limits<double>::denorm_min();
  ASSERT_GT(var, 0.0);
  std::feclearexcept(FE_OVERFLOW);
  const ShapeRate s = gamma_shape_rate(1.0, var);
  EXPECT_FALSE(std::fetestexcept(FE_OVERFLOW));
  EXPECT_EQ(s.beta, kInf);
  EXPECT_EQ(s.alpha, kInf);
  // A small mean over a subnormal variance stays finite: β = 1e-310/1e-320 = 1e10.
  const ShapeRate t = gamma_shape_rate(1e-310, 1e-320);
  EXPECT_NEAR(t.beta / 1e10, 1.0, 1e-2);  // subnormals carry few digits
  EXPECT_TRUE(std::isfinite(t.alpha));
  EXPECT_GT(t.alpha, 0.0);
}

TEST(GammaShapeRate, HugeMeanKeepsARepresentableShape) {
  // C̄ = 1e200, Var C = 1e395 is out of range; Var C = 1e300: C̄² = 1e400 overflows, α = 1e100 does not.
  std::feclearexcept(FE_OVERFLOW);
  const ShapeRate s = gamma_shape_rate(1e200, 1e300);
  EXPECT_FALSE(std::fetestexcept(FE_OVERFLOW));
  EXPECT_NEAR(s.beta / 1e-100, 1.0, 1e-12);
  EXPECT_NEAR(s.alpha / 1e100, 1.0, 1e-12);
  // A shape beyond the doubles is +∞ (the exponential limit), not a trap.
  const ShapeRate u = gamma_shape_rate(1e300, 1.0);
  EXPECT_FALSE(std::fetestexcept(FE_OVERFLOW));
  EXPECT_EQ(u.beta, 1e300);
  EXPECT_EQ(u.alpha, kInf);
}

}  // namespace
}  // namespace weft::transmittance
