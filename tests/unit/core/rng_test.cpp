#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "weft/core/rng.h"

namespace {

TEST(Pcg32, SameSeedAndStreamGiveSameSequence) {
  weft::Pcg32 a(42, 7);
  weft::Pcg32 b(42, 7);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(a.next_u32(), b.next_u32());
}

TEST(Pcg32, DistinctStreamsDiffer) {
  auto a = weft::stream_for(1, 0);
  auto b = weft::stream_for(1, 1);
  int equal = 0;
  for (int i = 0; i < 1000; ++i) equal += a.next_u32() == b.next_u32() ? 1 : 0;
  EXPECT_LT(equal, 3);
}

TEST(Pcg32, UniformPassesKolmogorovSmirnov) {
  auto rng = weft::stream_for(2024, 3);
  constexpr int kN = 100000;
  std::vector<double> u(kN);
  for (auto& x : u) x = rng.uniform();
  std::sort(u.begin(), u.end());
  double d = 0.0;
  for (int i = 0; i < kN; ++i) {
    d = std::max({d, std::abs((i + 1.0) / kN - u[i]), std::abs(u[i] - static_cast<double>(i) / kN)});
  }
  // Critical value of the KS statistic at significance 1e-3: 1.95 / sqrt(n).
  EXPECT_LT(d, 1.95 / std::sqrt(static_cast<double>(kN)));
  EXPECT_GE(u.front(), 0.0);
  EXPECT_LT(u.back(), 1.0);
}

TEST(Pcg32, UniformBelowStaysInRangeAndCoversIt) {
  auto rng = weft::stream_for(5, 5);
  std::vector<int> counts(7, 0);
  for (int i = 0; i < 70000; ++i) {
    const auto r = rng.uniform_below(7);
    ASSERT_LT(r, 7U);
    ++counts[r];
  }
  // Each count is Binomial(70000, 1/7): mean 10000, sd ~ 92.6; allow 5 sd.
  for (int c : counts) EXPECT_NEAR(c, 10000, 5 * 92.6);
}

}  // namespace
