#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "weft/core/error.h"

namespace {

TEST(Error, RequirePositiveRejectsNanZeroNegativeAndInf) {
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(weft::require_positive("sigma", bad), weft::Error) << bad;
  }
  EXPECT_EQ(weft::require_positive("sigma", 2.5), 2.5);
}

TEST(Error, MessageNamesTheParameter) {
  try {
    weft::require_non_negative("voxel size", -3.0);
    FAIL();
  } catch (const weft::Error& e) {
    EXPECT_NE(std::string(e.what()).find("voxel size"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

}  // namespace
