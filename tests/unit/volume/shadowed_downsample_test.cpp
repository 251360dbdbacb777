// The self-shadowing corrected downsampling (shadowed_downsample.h; docs/render.md §6d) against
// closed forms: a uniform block needs no correction, a half-empty block has two exact values
// (along the slab and across it), every block reproduces its mean transmittance along each axis,
// and the grid is a property of the cloth, not of its voxels, index origin or thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/volume/downsample.h"
#include "weft/volume/grid.h"
#include "weft/volume/shadowed_downsample.h"

namespace weft::volume {
namespace {

Grid filled(double h, int n, const std::function<float(int, int, int)>& value) {
  Grid g(h);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        if (const float v = value(i, j, k); v > 0.0F) g.set_value(i, j, k, v);
  return g;
}

/// A sparse random grid straddling negative indices, odd extents.
Grid random_grid(std::uint64_t seed, double h = 0.01) {
  Grid g(h);
  g.set_origin({0.1, -0.3, 0.7});
  Pcg32 rng(seed, 3);
  for (int i = -5; i < 12; ++i)
    for (int j = -9; j < 4; ++j)
      for (int k = 3; k < 22; ++k)
        if (rng.uniform() < 0.4) g.set_value(i, j, k, static_cast<float>(rng.uniform()));
  return g;
}

/// Calls `body(i, j, k)` over the union of both grids' active boxes.
void over_both(const Grid& a, const Grid& b, const std::function<void(int, int, int)>& body) {
  const IndexBox x = a.active_bbox();
  const IndexBox y = b.active_bbox();
  for (int i = std::min(x.min[0], y.min[0]); i <= std::max(x.max[0], y.max[0]); ++i)
    for (int j = std::min(x.min[1], y.min[1]); j <= std::max(x.max[1], y.max[1]); ++j)
      for (int k = std::min(x.min[2], y.min[2]); k <= std::max(x.max[2], y.max[2]); ++k) body(i, j, k);
}

TEST(ShadowedDownsample, UniformBlocksEqualTheLinearMeanBitForBit) {
  // Every column of a uniform block is equally deep: T̄ = e^{−σC·fh}, nothing to correct.
  const Grid fine = filled(0.01, 8, [](int, int, int) { return 0.3F; });
  for (int f : {1, 2, 4, 8}) {
    const ShadowedGrids s = shadowed_downsample(fine, f, 100.0);
    const Grid linear = downsample(fine, f);
    EXPECT_DOUBLE_EQ(s.isotropic.voxel_size(), linear.voxel_size());
    EXPECT_EQ(s.isotropic.active_voxel_count(), linear.active_voxel_count());
    over_both(s.isotropic, linear, [&](int i, int j, int k) {
      const float expected = linear.value(i, j, k);
      EXPECT_EQ(s.isotropic.value(i, j, k), expected) << "factor " << f;
      for (const Grid& g : s.per_axis) EXPECT_EQ(g.value(i, j, k), expected) << "factor " << f;
    });
  }
}

TEST(ShadowedDownsample, HalfEmptyBlockAlongAndAcrossTheSlab) {
  // One block of f = 8 voxels, the half x < 4 at C and the rest empty. Along x every column
  // crosses 4 full voxels: T̄_x = e^{−σC·fh/2}, value C/2 (the linear mean). Along y and z
  // half the columns are full and half empty: T̄ = (1 + e^{−σC·fh})/2.
  const int f = 8;
  const double h = 0.01;
  const double sigma = 100.0;
  for (const double c : {0.05, 0.5, 1.0}) {
    const Grid fine = filled(h, f, [&](int i, int, int) { return i < f / 2 ? static_cast<float>(c) : 0.0F; });
    const ShadowedGrids s = shadowed_downsample(fine, f, sigma);
    const double cf = static_cast<float>(c);
    const double tau = sigma * cf * f * h;
    const double across = -std::log((1.0 + std::exp(-tau)) / 2.0) / (sigma * f * h);
    EXPECT_NEAR(s.per_axis[0].value(0, 0, 0), cf / 2.0, 1e-6 * cf);
    EXPECT_NEAR(s.per_axis[1].value(0, 0, 0), across, 1e-6 * across);
    EXPECT_NEAR(s.per_axis[2].value(0, 0, 0), across, 1e-6 * across);
    EXPECT_NEAR(s.isotropic.value(0, 0, 0), (cf / 2.0 + 2.0 * across) / 3.0, 1e-6 * cf);
    EXPECT_LT(across, cf / 2.0);  // the gaps let light through: less extinction than the mean
  }
}

TEST(ShadowedDownsample, OpaqueColumnsStayFiniteInLogSpace) {
  // Columns of optical depth 2000 and 3000 (e^{−τ} underflows a double): T̄ = (e^{−2000} +
  // e^{−3000})/2, −ln T̄ = 2000 + ln 2 − log1p(e^{−1000}), the value −ln T̄/(σ f h).
  const int f = 4;
  const double h = 0.25;
  const double sigma = 1.0;
  // Along y and z: columns at i < 2 have τ = σ·h·4·2000 = 2000, the others 3000.
  const Grid fine = filled(h, f, [&](int i, int, int) { return i < 2 ? 2000.0F : 3000.0F; });
  const ShadowedGrids s = shadowed_downsample(fine, f, sigma);
  const double expected = (2000.0 + std::log(2.0)) / (sigma * f * h);  // f·h = 1
  for (int a : {1, 2}) {
    const double v = s.per_axis[static_cast<std::size_t>(a)].value(0, 0, 0);
    EXPECT_TRUE(std::isfinite(v));
    EXPECT_NEAR(v, expected, 1e-6 * expected) << "axis " << a;
  }
}

TEST(ShadowedDownsample, EveryBlockReproducesItsMeanTransmittancePerAxis) {
  // The definition, computed here independently with Grid::value: exp(−σ·value_a·f·h) is the
  // mean of the f² columns' e^{−τ}; and 0 ≤ value_a ≤ the linear mean (Jensen).
  const Grid fine = random_grid(4);
  const double sigma = 150.0;
  const double h = fine.voxel_size();
  for (int f : {2, 3, 5}) {
    const ShadowedGrids s = shadowed_downsample(fine, f, sigma);
    const Grid linear = downsample(fine, f);
    const IndexBox cb = linear.active_bbox();
    const std::array<int, 3> lo = fine.active_bbox().min;  // the blocks' anchor (volume/block_lattice.h)
    for (int bi = cb.min[0]; bi <= cb.max[0]; ++bi) {
      for (int bj = cb.min[1]; bj <= cb.max[1]; ++bj) {
        for (int bk = cb.min[2]; bk <= cb.max[2]; ++bk) {
          for (int a = 0; a < 3; ++a) {
            double t_sum = 0.0;
            for (int u = 0; u < f; ++u) {
              for (int v = 0; v < f; ++v) {
                double tau = 0.0;
                for (int w = 0; w < f; ++w) {
                  std::array<int, 3> ijk{};
                  ijk[static_cast<std::size_t>(a)] = w;
                  ijk[static_cast<std::size_t>((a + 1) % 3)] = u;
                  ijk[static_cast<std::size_t>((a + 2) % 3)] = v;
                  tau +=
                      sigma * h * fine.value(lo[0] + bi * f + ijk[0], lo[1] + bj * f + ijk[1], lo[2] + bk * f + ijk[2]);
                }
                t_sum += std::exp(-tau);
              }
            }
            const double t_bar = t_sum / (f * f);
            const double value = s.per_axis[static_cast<std::size_t>(a)].value(bi, bj, bk);
            EXPECT_NEAR(std::exp(-sigma * value * f * h), t_bar, 1e-6 * t_bar + 1e-12)
                << "factor " << f << " block " << bi << "," << bj << "," << bk << " axis " << a;
            EXPECT_GE(value, 0.0);
            EXPECT_LE(value, linear.value(bi, bj, bk));
          }
        }
      }
    }
  }
}

TEST(ShadowedDownsample, RefiningTheVoxelsChangesNothing) {
  // The same cloth at voxels h/2 (each voxel split in 2³) coarsened 2f gives the grid of h at f.
  const Grid coarse_voxels = random_grid(6, 0.02);
  Grid fine_voxels(0.01);
  fine_voxels.set_origin(coarse_voxels.origin());
  const IndexBox b = coarse_voxels.active_bbox();
  for (int i = b.min[0]; i <= b.max[0]; ++i)
    for (int j = b.min[1]; j <= b.max[1]; ++j)
      for (int k = b.min[2]; k <= b.max[2]; ++k)
        if (const float v = coarse_voxels.value(i, j, k); v > 0.0F)
          for (int c = 0; c < 8; ++c) fine_voxels.set_value(2 * i + (c & 1), 2 * j + (c >> 1 & 1), 2 * k + (c >> 2), v);
  for (int f : {2, 3}) {
    const ShadowedGrids a = shadowed_downsample(coarse_voxels, f, 80.0);
    const ShadowedGrids r = shadowed_downsample(fine_voxels, 2 * f, 80.0);
    EXPECT_DOUBLE_EQ(a.isotropic.voxel_size(), r.isotropic.voxel_size());
    for (std::size_t ax = 0; ax < 3; ++ax) {
      over_both(a.per_axis[ax], r.per_axis[ax], [&](int i, int j, int k) {
        const double x = a.per_axis[ax].value(i, j, k);
        EXPECT_NEAR(r.per_axis[ax].value(i, j, k), x, 1e-6 * x + 1e-9) << "factor " << f << " axis " << ax;
      });
    }
  }
}

TEST(ShadowedDownsample, ShiftingTheIndexOriginChangesNothingInTheWorld) {
  // The same voxels at another index origin (any whole-voxel shift, not only whole blocks) and
  // the origin moved back: the blocks are anchored to the cloth (volume/block_lattice.h), so
  // both coarse grids hold the same values at the same coarse indices and world positions. Sums
  // may run in another order over the moved leaves: equal to float rounding.
  const Grid g = random_grid(9);
  const int f = 3;
  const ShadowedGrids a = shadowed_downsample(g, f, 120.0);
  const Grid linear = downsample(g, f);
  for (const std::array<int, 3> shift : {std::array<int, 3>{1, 2, 0}, {-7, -3, -1}, {1001, -513, 37}}) {
    Grid moved(g.voxel_size());
    auto o = g.origin();
    for (std::size_t x = 0; x < 3; ++x) o[x] -= shift[x] * g.voxel_size();
    moved.set_origin(o);
    const IndexBox b = g.active_bbox();
    for (int i = b.min[0]; i <= b.max[0]; ++i)
      for (int j = b.min[1]; j <= b.max[1]; ++j)
        for (int k = b.min[2]; k <= b.max[2]; ++k)
          if (const float v = g.value(i, j, k); v > 0.0F) moved.set_value(i + shift[0], j + shift[1], k + shift[2], v);
    const ShadowedGrids m = shadowed_downsample(moved, f, 120.0);
    const Grid moved_linear = downsample(moved, f);
    SCOPED_TRACE(testing::Message() << "shift " << shift[0] << "," << shift[1] << "," << shift[2]);
    for (std::size_t x = 0; x < 3; ++x) {
      EXPECT_NEAR(m.isotropic.origin()[x], a.isotropic.origin()[x], 1e-9);
      EXPECT_NEAR(moved_linear.origin()[x], linear.origin()[x], 1e-9);
    }
    EXPECT_EQ(m.isotropic.active_voxel_count(), a.isotropic.active_voxel_count());
    EXPECT_EQ(moved_linear.active_voxel_count(), linear.active_voxel_count());
    over_both(a.isotropic, m.isotropic, [&](int i, int j, int k) {
      const float x = a.isotropic.value(i, j, k);
      EXPECT_NEAR(m.isotropic.value(i, j, k), x, 1e-6F * x);
      for (std::size_t ax = 0; ax < 3; ++ax) {
        const float y = a.per_axis[ax].value(i, j, k);
        EXPECT_NEAR(m.per_axis[ax].value(i, j, k), y, 1e-6F * y);
      }
      const float l = linear.value(i, j, k);
      EXPECT_NEAR(moved_linear.value(i, j, k), l, 1e-6F * l);
    });
  }
}

TEST(ShadowedDownsample, SameValuesForAnyThreadCount) {
  const Grid g = random_grid(2);
  const ShadowedGrids all = shadowed_downsample(g, 2, 90.0);
  const ThreadLimit one(1);
  const ShadowedGrids single = shadowed_downsample(g, 2, 90.0);
  over_both(all.isotropic, single.isotropic,
            [&](int i, int j, int k) { EXPECT_EQ(all.isotropic.value(i, j, k), single.isotropic.value(i, j, k)); });
}

TEST(ShadowedDownsample, RejectsBadInput) {
  const Grid g = random_grid(1);
  EXPECT_THROW((void)shadowed_downsample(Grid(1.0), 2, 1.0), Error);
  EXPECT_THROW((void)shadowed_downsample(g, 0, 1.0), Error);
  EXPECT_THROW((void)shadowed_downsample(g, 5000, 1.0), Error);
  EXPECT_THROW((void)shadowed_downsample(g, 2, 0.0), Error);
  EXPECT_THROW((void)shadowed_downsample(g, 2, std::nan("")), Error);
}

}  // namespace
}  // namespace weft::volume
