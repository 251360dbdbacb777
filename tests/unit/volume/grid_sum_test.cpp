// Grid::sum: every active value once (tiles weighted by their voxels), the same double for any
// thread count.
#include <gtest/gtest.h>

#include <openvdb/openvdb.h>
#include <tbb/global_control.h>

#include <bit>
#include <cmath>
#include <cstdint>

#include "weft/core/rng.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

TEST(GridSum, EveryVoxelAndTileOnceTheSameForAnyThreadCount) {
  Grid g(0.1);
  Pcg32 rng(5);
  long double exact = 0.0L;
  for (int n = 0; n < 200000; ++n) {
    const int i = static_cast<int>(rng.uniform() * 300.0) - 150;
    const int j = static_cast<int>(rng.uniform() * 300.0) - 150;
    const int k = static_cast<int>(rng.uniform() * 40.0);
    const float v = static_cast<float>(rng.uniform());
    exact -= g.value(i, j, k);  // a voxel set twice keeps its last value
    g.set_value(i, j, k, v);
    exact += v;
  }
  // An active tile of 8³ voxels and one of 128³, and an inactive voxel that must not count.
  g.impl().grid->tree().addTile(1, openvdb::Coord(1024, 0, 0), 0.25F, true);
  g.impl().grid->tree().addTile(2, openvdb::Coord(4096, 0, 0), 0.5F, true);
  g.impl().grid->tree().setValueOff(openvdb::Coord(2000, 0, 0), 7.0F);
  exact += 0.25L * 512.0L + 0.5L * 128.0L * 128.0L * 128.0L;
  double one = 0.0;
  {
    const tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = g.sum();
  }
  double two = 0.0;
  {
    const tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = g.sum();
  }
  EXPECT_EQ(std::bit_cast<std::uint64_t>(one), std::bit_cast<std::uint64_t>(two));
  // Per-leaf double sums, then a few thousand leaves in order: the rounding (≲ √n·2⁻⁵³ of the
  // total for n ≈ 2·10⁵ terms, ≈ 5·10⁻¹⁴) stays far inside 10⁻¹²; a missed tile or a counted
  // inactive voxel moves the sum by ≥ 0.25.
  EXPECT_NEAR(one, static_cast<double>(exact), 1e-12 * static_cast<double>(exact));
}

}  // namespace
}  // namespace weft::volume
