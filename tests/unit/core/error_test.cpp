#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

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

// What a message quotes cannot break it: a path or key with a newline, a NUL or other control
// characters still prints as one whole line (what() is a C string: NUL cut it short).
TEST(Error, AMessageStaysOneWholeLineWhateverItQuotes) {
  const std::string key("w\0x", 3);
  const weft::Error e(fmt::format("file 'no\nsuch.vdb', key '{}', bell \a, tab\there, done", key));
  EXPECT_STREQ(e.what(), "file 'no\\nsuch.vdb', key 'w\\0x', bell \\x07, tab\there, done");
  EXPECT_EQ(weft::Error::one_line("a\r\x7f"), "a\\r\\x7f");
  EXPECT_EQ(weft::Error::one_line("plain µm text"), "plain µm text");  // UTF-8 bytes are not control characters
}

}  // namespace
