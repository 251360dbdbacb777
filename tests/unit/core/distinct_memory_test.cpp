// require_distinct (core/distinct.h): a repeated case is named; memory_budget_bytes and
// format_bytes (core/memory.h): a given limit never reads as 0 (the guards' "default").
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "weft/core/distinct.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"

namespace weft {
namespace {

std::string error_of(const auto& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

TEST(RequireDistinct, NamesTheLaterOfTwoEqualItems) {
  EXPECT_NO_THROW(require_distinct("eta", std::vector<double>{-0.5, 0.0, 0.5}));
  EXPECT_NO_THROW(require_distinct("eta", std::vector<double>{}));
  EXPECT_EQ(error_of([] {
              require_distinct("eta", std::vector<double>{0.5, -0.5, 0.25, -0.5, 0.5});
            }),
            "eta: -0.5 is given twice");
  // -0 and +0 are the same case.
  EXPECT_EQ(error_of([] { require_distinct("theta", std::vector<double>{0.0, -0.0}); }), "theta: -0 is given twice");
}

TEST(RequireDistinct, ComparesByKeyAndLabelsByIndex) {
  // Directions are the same case when their unit vectors are: (1, 0, 0) and (3, 0, 0).
  const std::vector<std::array<double, 3>> dirs{{0, 1, 0}, {1, 0, 0}, {3, 0, 0}};
  const auto unit = [](const std::array<double, 3>& d) {
    const double n = std::hypot(d[0], d[1], d[2]);
    return std::array<double, 3>{d[0] / n, d[1] / n, d[2] / n};
  };
  EXPECT_EQ(error_of([&] {
              require_distinct(
                  "--direction", dirs, [](std::size_t i) { return std::to_string(i); }, unit);
            }),
            "--direction: 2 is given twice");
}

TEST(MemoryBudget, ZeroIsTheDefaultAndAGivenLimitIsAtLeastOneByte) {
  EXPECT_EQ(memory_budget_bytes("m", 0.0), default_memory_budget());
  EXPECT_EQ(memory_budget_bytes("m", 1.0), 1024U * 1024U);
  EXPECT_EQ(memory_budget_bytes("m", 1e-300), 1U);
  EXPECT_EQ(memory_budget_bytes("m", 1e-320), 1U);                   // subnormal
  EXPECT_EQ(memory_budget_bytes("m", 1.5 / (1024.0 * 1024.0)), 2U);  // rounded up
  EXPECT_EQ(memory_budget_bytes("m", 1e300), std::numeric_limits<std::uint64_t>::max());
  for (const double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_NE(error_of([&] { (void)memory_budget_bytes("--max-memory-mb", bad); }).find("--max-memory-mb"),
              std::string::npos)
        << bad;
  }
}

TEST(MemoryBudget, FormatBytesSaysOneByte) {
  EXPECT_EQ(format_bytes(1), "1 byte");
  EXPECT_EQ(format_bytes(2), "2 bytes");
  EXPECT_EQ(format_bytes(1536), "1.5 KiB");
}

// A huge estimate is said in a unit that keeps it short, up to EiB; a count that rounds to 1024 of
// a unit is said in the next one.
TEST(MemoryBudget, FormatBytesKeepsHugeCountsShort) {
  EXPECT_EQ(format_bytes(1ULL << 40), "1.00 TiB");
  EXPECT_EQ(format_bytes((1ULL << 40) - 1), "1.00 TiB");
  EXPECT_EQ(format_bytes((1ULL << 20) - 1), "1.0 MiB");
  EXPECT_EQ(format_bytes(3ULL << 50), "3.00 PiB");
  EXPECT_EQ(format_bytes(std::numeric_limits<std::uint64_t>::max()), "16.00 EiB");
  for (std::uint64_t b = 1024; b < std::numeric_limits<std::uint64_t>::max() / 3; b = b * 3 + 1) {
    const std::string text = format_bytes(b);
    EXPECT_LE(text.size(), 11U) << text;  // "1023.95 PiB" at most
  }
}

// An estimate over a budget never reads as equal to it: the decimals grow until the texts differ,
// in the same unit, down to exact bytes; counts that differ always print differently.
TEST(MemoryBudget, BytesApartDifferWhenTheCountsDo) {
  EXPECT_EQ(format_bytes_apart(6836715, 6815744), (std::pair<std::string, std::string>{"6.52 MiB", "6.50 MiB"}));
  EXPECT_EQ(format_bytes_apart(3 << 20, 1 << 10), (std::pair<std::string, std::string>{"3.0 MiB", "1.0 KiB"}));
  EXPECT_EQ(format_bytes_apart(1ULL << 40, (1ULL << 40) - 1).second, "1023.999999999 GiB");
  for (std::uint64_t a = 1000000; a < 1000000000; a = a * 3 + 17) {
    const auto [x, y] = format_bytes_apart(a + 1, a);
    EXPECT_NE(x, y) << a;
  }
}

}  // namespace
}  // namespace weft
