// number_name: numbers in file names read back as themselves, so distinct values never share a
// file (sim2d's charts per eta, the study matrix's tilt folders).
#include "weft/core/number_name.h"

#include <cmath>
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

}  // namespace
}  // namespace weft
