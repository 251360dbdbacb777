// parse_number: the whole text is the number, or there is none; exact for 17 digits. (Its locale
// independence is std::from_chars's; this machine and CI have no decimal-comma locale to show it.)
#include "weft/core/parse_number.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace weft {
namespace {

TEST(ParseNumber, ReadsWholeNumbers) {
  EXPECT_EQ(parse_number("0.5"), 0.5);
  EXPECT_EQ(parse_number("-3e-7"), -3e-7);
  EXPECT_EQ(parse_number("+2"), 2.0);
  EXPECT_EQ(parse_number("1E3"), 1000.0);
  EXPECT_TRUE(std::isinf(*parse_number("inf")));
  EXPECT_TRUE(std::isnan(*parse_number("nan")));
}

TEST(ParseNumber, SubnormalsAreNumbers) {
  // strtod sets ERANGE for them; they are doubles all the same (Python's float() reads them too).
  EXPECT_EQ(parse_number("1e-320"), 1e-320);
  EXPECT_EQ(parse_number("-4.9e-324"), -std::numeric_limits<double>::denorm_min());
  // Past double's range either way is not a number: 1e-400 would silently read as 0.
  EXPECT_FALSE(parse_number("1e-400").has_value());
  EXPECT_FALSE(parse_number("1e400").has_value());
}

TEST(ParseNumber, RefusesAnythingAroundTheNumber) {
  for (const char* bad : {"", " 1", "1 ", "1mm", "0x", "--1", "+-1", "+", "1,5", "one", "1e", "1e999"})
    EXPECT_FALSE(parse_number(bad).has_value()) << "'" << bad << "'";
}

TEST(ParseNumber, RoundTripsSeventeenDigits) {
  // What beams.csv's record line writes ({:.17g}) reads back to the same double.
  for (const double x : {106.10329539459694, 1.0 / 3.0, std::numeric_limits<double>::min(), 6.02214076e23}) {
    const std::string text = fmt::format("{:.17g}", x);
    ASSERT_TRUE(parse_number(text).has_value()) << text;
    EXPECT_EQ(*parse_number(text), x) << text;
  }
}

// An option's number: the blanks around it are not part of it; what is refused is said as what it is.
TEST(ParseNumber, OptionNumbersDropTheBlanksAroundThem) {
  EXPECT_EQ(parse_option_number(" 2"), 2.0);
  EXPECT_EQ(parse_option_number("2 \t"), 2.0);
  EXPECT_EQ(parse_option_number("\t-0.5 "), -0.5);
  for (const char* bad : {"", "   ", "1 2", "0x10", "1e999"})
    EXPECT_FALSE(parse_option_number(bad).has_value()) << "'" << bad << "'";
  EXPECT_EQ(number_problem(" 2 "), "");
  EXPECT_EQ(number_problem("0x1p3"), "a hexadecimal number (write it in decimal)");
  EXPECT_EQ(number_problem("-0X10"), "a hexadecimal number (write it in decimal)");
  EXPECT_EQ(number_problem("1e309"), "past double's range");
  EXPECT_EQ(number_problem("-1e-400"), "past double's range");
  for (const char* bad : {"", "abc", "1mm", "1e", "+-1"}) EXPECT_EQ(number_problem(bad), "not a number") << bad;
}

}  // namespace
}  // namespace weft
