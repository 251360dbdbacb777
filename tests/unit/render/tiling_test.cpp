// The render's work units (render/tiling.h): every tile once, and a scrambled order in which
// every leading share of the units covers the whole film, which is what the progress bar's rate
// and ETA assume.
#include "weft/render/tiling.h"

#include <algorithm>
#include <cstddef>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

namespace weft::render {
namespace {

TEST(Tiling, EveryTileIsRenderedByExactlyOneUnit) {
  for (const auto& [w, h, spp] : {std::tuple{64, 64, 1024},
                                  {256, 256, 64},
                                  {1024, 768, 8},
                                  {320, 240, 16},
                                  {1, 1, 1},
                                  {37, 5, 3},
                                  {1000, 1, 1}}) {
    const Tiling tiling(w, h, spp);
    std::vector<int> seen(tiling.count(), 0);
    for (std::size_t u = 0; u < tiling.count(); ++u) {
      ASSERT_LT(tiling.tile(u), tiling.count());
      ++seen[tiling.tile(u)];
    }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; })) << w << "x" << h;
  }
}

// In row order the first units are the film's top rows only. Scrambled, any leading share of 64
// units or more falls in the top and bottom halves, and in the left and right halves, of the film
// in proportion: within 0.1 (a film whose tile counts are powers of two is exact at every 4^k
// units; others skip the keys past their last tile, 0.04 at worst on these films).
TEST(Tiling, EveryLeadingShareOfTheUnitsSpreadsOverTheWholeFilm) {
  for (const auto& [w, h, spp] : {std::tuple{320, 240, 16}, {1024, 768, 8}, {256, 256, 64}, {64, 64, 1024}}) {
    const Tiling tiling(w, h, spp);
    const std::size_t n = tiling.count();
    std::size_t top = 0;
    std::size_t left = 0;
    for (std::size_t u = 0; u < n; ++u) {
      const std::size_t t = tiling.tile(u);
      const auto tx = static_cast<int>(t % static_cast<std::size_t>(tiling.tiles_x));
      const auto ty = static_cast<int>(t / static_cast<std::size_t>(tiling.tiles_x));
      if (2 * ty < tiling.tiles_y) ++top;
      if (2 * tx < tiling.tiles_x) ++left;
      const double k = static_cast<double>(u + 1);
      if (u + 1 >= 64) {
        EXPECT_NEAR(static_cast<double>(top) / k, 0.5, 0.1) << w << "x" << h << " after " << u + 1 << " units";
        EXPECT_NEAR(static_cast<double>(left) / k, 0.5, 0.1) << w << "x" << h << " after " << u + 1 << " units";
      }
    }
  }
}

}  // namespace
}  // namespace weft::render
