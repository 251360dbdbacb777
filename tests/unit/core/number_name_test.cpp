// number_name: numbers in file names read back as themselves, so distinct values never share a
// file (sim2d's charts per eta, the study matrix's tilt folders).
#include "weft/core/number_name.h"

#include <cmath>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "weft/core/parse_number.h"

namespace weft {
namespace {

// Values a fixed number of digits merges (0.996 and 0.999 at two decimals, 30 and 30.00000001 at
// six significant digits), their neighbouring doubles, and the extremes of sim2d's eta range.
std::vector<double> close_values() {
  std::vector<double> v{0.996, 0.999, 0.9999, 0.001, 0.004, 30.0, 30.00000001, 1e-5, -0.5, -1.0, 45.0};
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    v.push_back(std::nextafter(v[i], 2.0 * v[i] + 1.0));
    v.push_back(std::nextafter(v[i], -2.0 * std::abs(v[i]) - 1.0));
  }
  return v;
}

TEST(NumberName, ReadsBackAsTheSameNumber) {
  for (const double x : close_values()) {
    EXPECT_EQ(parse_number(number_name(x)), x) << number_name(x);
    EXPECT_EQ(parse_number(signed_number_name(x)), x) << signed_number_name(x);
  }
}

TEST(NumberName, DistinctValuesGetDistinctNames) {
  const std::vector<double> values = close_values();
  std::set<double> distinct(values.begin(), values.end());
  std::set<std::string> names;
  std::set<std::string> signed_names;
  for (const double x : distinct) {
    names.insert(number_name(x));
    signed_names.insert(signed_number_name(x));
  }
  EXPECT_EQ(names.size(), distinct.size());
  EXPECT_EQ(signed_names.size(), distinct.size());
}

TEST(NumberName, MinusZeroIsZeroAndTheSignIsAlwaysWritten) {
  EXPECT_EQ(number_name(-0.0), number_name(0.0));
  EXPECT_EQ(signed_number_name(-0.0), "+0");
  EXPECT_EQ(signed_number_name(0.5), "+0.5");
  EXPECT_EQ(signed_number_name(-0.5), "-0.5");
  EXPECT_EQ(number_name(45.0), "45");  // the study matrix's folder names as before
}

// A bound printed in a message, given back, is accepted: a lower bound is never printed below
// itself nor an upper bound above, over random magnitudes and the values that round the wrong way.
TEST(BoundText, PrintedBoundsAreOnTheAcceptedSide) {
  EXPECT_EQ(bound_text(std::cbrt(3e-15), BoundSide::at_least), "1.443e-05");  // OpenVDB's smallest voxel
  EXPECT_EQ(bound_text(std::cbrt(3e-15), BoundSide::at_most), "1.442e-05");
  EXPECT_EQ(bound_text(2.5, BoundSide::at_least), "2.5");
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> exponent(-300.0, 300.0);
  for (int i = 0; i < 20000; ++i) {
    const double x = std::pow(10.0, exponent(rng)) * (i % 2 == 0 ? 1.0 : -1.0);
    const std::optional<double> low = parse_number(bound_text(x, BoundSide::at_least));
    const std::optional<double> high = parse_number(bound_text(x, BoundSide::at_most));
    ASSERT_TRUE(low && high) << x;
    EXPECT_GE(*low, x) << bound_text(x, BoundSide::at_least);
    EXPECT_LE(*high, x) << bound_text(x, BoundSide::at_most);
    EXPECT_LE(std::fabs(*low - x), 1e-3 * std::fabs(x)) << x;  // still 4 digits' worth of x
    EXPECT_LE(std::fabs(*high - x), 1e-3 * std::fabs(x)) << x;
  }
}

}  // namespace
}  // namespace weft
