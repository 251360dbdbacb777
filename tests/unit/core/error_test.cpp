#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "error_matchers.h"
#include "weft/core/error.h"

namespace {

TEST(Error, RequirePositiveRejectsNanZeroNegativeAndInf) {
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(weft::require_positive("sigma", bad), weft::Error) << bad;
  }
  EXPECT_EQ(weft::require_positive("sigma", 2.5), 2.5);
}

TEST(Error, MessageNamesTheParameter) {
  EXPECT_THAT([] { weft::require_non_negative("voxel size", -3.0); },
              weft::test::throws_one_line_error_with({"voxel size"}));
}

}  // namespace
