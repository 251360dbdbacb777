#include "weft/viz/chart_items.h"

#include <cmath>

#include <gtest/gtest.h>

namespace weft::viz::detail {
namespace {

double on_length(const std::vector<float>& pieces) {
  double total = 0.0;
  for (std::size_t i = 0; i + 3 < pieces.size(); i += 4) {
    total += std::hypot(pieces[i + 2] - pieces[i], pieces[i + 3] - pieces[i + 1]);
  }
  return total;
}

constexpr std::array<float, 4> kEverywhere{-1e9f, 1e9f, -1e9f, 1e9f};

TEST(DashPolyline, OnFractionFollowsThePatternAcrossVertices) {
  // An L of 98 + 62 px with a 3 on / 5 off pattern: the phase carries over the corner, which
  // falls inside the 13th dash (96..99).
  const std::vector<float> xy{0, 0, 98, 0, 98, 62};
  const auto pieces = dash_polyline(xy, {3.0f, 5.0f}, kEverywhere);
  ASSERT_EQ(pieces.size() % 4, 0U);
  EXPECT_NEAR(on_length(pieces), 160.0 * 3.0 / 8.0, 1e-3);
  // The first piece starts at the first vertex and is 3 px long.
  EXPECT_FLOAT_EQ(pieces[0], 0.0f);
  EXPECT_FLOAT_EQ(pieces[2], 3.0f);
  // 20 dashes along the path, one split by the corner: 21 pieces; the split one resumes there.
  ASSERT_EQ(pieces.size() / 4, 21U);
  EXPECT_FLOAT_EQ(pieces[12 * 4 + 2], 98.0f);
  EXPECT_FLOAT_EQ(pieces[13 * 4 + 3], 1.0f);
}

TEST(DashPolyline, ClipsToTheBoxAndSkipsSegmentsOutside) {
  const std::vector<float> xy{-1000, 10, 1000, 10, 1000, 5000};
  const auto pieces = dash_polyline(xy, {2.0f, 2.0f}, {0.0f, 100.0f, 0.0f, 100.0f});
  ASSERT_FALSE(pieces.empty());
  for (std::size_t i = 0; i < pieces.size(); i += 2) {
    EXPECT_GE(pieces[i], 0.0f);
    EXPECT_LE(pieces[i], 100.0f);
    EXPECT_FLOAT_EQ(pieces[i + 1], 10.0f);
  }
  EXPECT_NEAR(on_length(pieces), 50.0, 2.5);
}

TEST(DashPolyline, DegenerateInputGivesNothing) {
  EXPECT_TRUE(dash_polyline({1, 1}, {2.0f, 2.0f}, kEverywhere).empty());
  EXPECT_TRUE(dash_polyline({1, 1, 1, 1}, {2.0f, 2.0f}, kEverywhere).empty());
  EXPECT_TRUE(dash_polyline({0, 0, 10, 0}, {}, kEverywhere).empty());
}

}  // namespace
}  // namespace weft::viz::detail
