// Majorant grids, their traversal and the trackers built on them (weft/volume/majorants.h):
// cells of 8³ voxels anchored at the active voxels' lower corner bound every value a point lookup
// can return (faces, negative indices, tiles, axis-aligned rays, another index origin), and
// delta/ratio tracking and the optical-depth march estimate what the exact DDA computes.
// Statistical checks use fixed seeds and 5σ.
#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/majorants.h"

namespace weft::volume {
namespace {

/// 24³ voxels of size 1/24 over [-0.5, 0.5]³ starting at index -12 (negative indices, three
/// leaves per axis): dense in one corner, thin elsewhere, with holes.
Grid varying_grid() {
  Grid grid(1.0 / 24.0, "density");
  for (int i = -12; i < 12; ++i)
    for (int j = -12; j < 12; ++j)
      for (int k = -12; k < 12; ++k) {
        if (((i + 2 * j + 3 * k) % 7 + 7) % 7 == 0) continue;  // holes
        grid.set_value(i, j, k, i < 0 && j < 0 ? 0.9f : 0.05f * static_cast<float>(1 + (k + 12) % 3));
      }
  grid.set_origin({0.0, 0.0, 0.0});
  return grid;
}

double value_at_point(const Grid& g, double x, double y, double z) {
  const auto o = g.origin();
  const double h = g.voxel_size();
  return g.value(static_cast<int>(std::floor((x - o[0]) / h)), static_cast<int>(std::floor((y - o[1]) / h)),
                 static_cast<int>(std::floor((z - o[2]) / h)));
}

TEST(MajorantGrid, CellsAreAnchoredAtTheActiveCornerAndDilatedByOneVoxel) {
  // The active voxels start at (-1, 2, 2): cell K covers voxels (-1, 2, 2) + 8K … + 8K + 7, so
  // cell 0 spans x = -1 … 6 across two leaves and cell 1 starts at x = 7.
  Grid g(0.5, "density");
  g.set_value(-1, 2, 2, 1.0f);  // the corner, on cell (0,0,0)'s faces: raises cells (-1…0)³ too
  g.set_value(3, 5, 5, 2.0f);   // interior of cell (0,0,0)
  g.set_value(6, 5, 5, 5.0f);   // on cell (0,0,0)'s +x face (leaf (0,0,0)): raises cell (1,0,0)
  g.set_value(9, 5, 5, 6.0f);   // interior of cell (1,0,0) (leaf (8,0,0))
  g.set_value(7, 6, 6, 0.5f);   // leaf (0,0,0) but cell (1,0,0), on its -x face
  const MajorantGrid m(g);
  const Grid& c = m.cells();
  EXPECT_DOUBLE_EQ(c.voxel_size(), 4.0);
  EXPECT_EQ(c.value(0, 0, 0), 5.0f);
  EXPECT_EQ(c.value(1, 0, 0), 6.0f);
  EXPECT_EQ(c.value(-1, 0, 0), 1.0f);
  EXPECT_EQ(c.value(-1, -1, -1), 1.0f);
  EXPECT_EQ(c.value(0, 1, 0), 0.0f);  // nothing within a voxel of that cell
  EXPECT_EQ(c.value(2, 0, 0), 0.0f);
  EXPECT_DOUBLE_EQ(m.max_value(), 6.0);
  // Cell 0 starts at the world corner of voxel (-1, 2, 2).
  const auto o = g.origin();
  EXPECT_EQ(c.origin(), (std::array<double, 3>{o[0] - 0.5, o[1] + 1.0, o[2] + 1.0}));
}

// The same voxels at another index origin (shifts that are not multiples of 8, the world origin
// moved back; voxels of 1/32 keep every position exact): the same cells in the world, and the
// same tracking draw for draw (docs/render.md §5 "Majorant cells anchored to the cloth").
TEST(MajorantGrid, ShiftingTheIndexOriginChangesNothingInTheWorld) {
  const double h = 1.0 / 32.0;
  const auto grid_at = [&](const std::array<int, 3>& shift) {
    Grid g(h, "density");
    for (int i = 0; i < 24; ++i)
      for (int j = 0; j < 24; ++j)
        for (int k = 0; k < 24; ++k) {
          if ((i + 2 * j + 3 * k) % 7 == 0) continue;  // holes
          g.set_value(i + shift[0], j + shift[1], k + shift[2],
                      i < 12 && j < 12 ? 0.9f : 0.05f * static_cast<float>(1 + k % 3));
        }
    g.set_origin({-h * shift[0], -h * shift[1], -h * shift[2]});
    return g;
  };
  const Grid base = grid_at({0, 0, 0});
  const MajorantGrid mb(base);
  MajorantTracker tb(base, mb);
  for (const std::array<int, 3> shift : {std::array<int, 3>{5, -7, 13}, {-1, 3, 4}, {1001, -515, 37}}) {
    SCOPED_TRACE(testing::Message() << "shift " << shift[0] << "," << shift[1] << "," << shift[2]);
    const Grid moved = grid_at(shift);
    const MajorantGrid mm(moved);
    EXPECT_EQ(mm.cells().origin(), mb.cells().origin());
    EXPECT_EQ(mm.active_cells(), mb.active_cells());
    EXPECT_EQ(mm.cells().sum(), mb.cells().sum());
    for (int i = -1; i <= 3; ++i)
      for (int j = -1; j <= 3; ++j)
        for (int k = -1; k <= 3; ++k) EXPECT_EQ(mm.cells().value(i, j, k), mb.cells().value(i, j, k));
    MajorantTracker tm(moved, mm);
    Pcg32 ray_rng(3);
    for (int trial = 0; trial < 200; ++trial) {
      const std::array<double, 3> o{ray_rng.uniform() * 2 - 0.5, ray_rng.uniform() * 2 - 0.5, -0.5};
      const std::array<double, 3> d{ray_rng.uniform() - 0.5, ray_rng.uniform() - 0.5, 1.0};
      Pcg32 ra(100 + trial);
      Pcg32 rb(100 + trial);
      const TrackedCollision ca = tb.delta_track(Ray{o, d}, 0.0, 3.0, 20.0, ra);
      const TrackedCollision cb = tm.delta_track(Ray{o, d}, 0.0, 3.0, 20.0, rb);
      EXPECT_EQ(ca.collided, cb.collided);
      EXPECT_EQ(ca.t, cb.t);
      EXPECT_EQ(tb.ratio_track(Ray{o, d}, 0.0, 3.0, 20.0, ra), tm.ratio_track(Ray{o, d}, 0.0, 3.0, 20.0, rb));
    }
  }
}

TEST(MajorantGrid, ActiveTilesRaiseEveryCellTheyTouch) {
  Grid g(1.0, "density");
  auto& tree = g.impl().grid->tree();
  tree.addTile(2, openvdb::Coord(0, 0, 0), 0.75f, true);  // a 128³ tile (a child of the upper internal node)
  const MajorantGrid m(g);
  EXPECT_EQ(m.cells().value(0, 0, 0), 0.75f);
  EXPECT_EQ(m.cells().value(15, 15, 15), 0.75f);
  EXPECT_EQ(m.cells().value(16, 3, 3), 0.75f);  // dilation across the tile's face
  EXPECT_EQ(m.cells().value(17, 3, 3), 0.0f);
}

// The walk tiles the clipped ray in order, and at points inside each segment the value is
// bounded by the segment's majorant; axis-aligned rays (zero direction components) and rays
// along cell faces included.
TEST(MajorantTracker, WalkTilesTheRayAndBoundsEveryPointValue) {
  const Grid g = varying_grid();
  const MajorantGrid m(g);
  MajorantTracker tracker(g, m);
  Pcg32 rng(5);
  int segments = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::array<double, 3> o{rng.uniform() * 3 - 1.5, rng.uniform() * 3 - 1.5, rng.uniform() * 3 - 1.5};
    std::array<double, 3> d{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
    if (trial % 4 == 0) d = {0.0, 0.0, trial % 8 == 0 ? 1.0 : -1.0};
    if (trial % 12 == 1) {  // exactly on a cell face x = 0 (a leaf boundary), along +y
      o = {0.0, -1.0, rng.uniform() - 0.5};
      d = {0.0, 1.0, 0.0};
    }
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (double& x : d) x /= len;
    double last = -1.0;
    bool first = true;
    tracker.walk(Ray{o, d}, 0.0, 10.0, [&](double ta, double tb, double majorant) {
      ++segments;
      EXPECT_LT(ta, tb);
      if (!first) {
        EXPECT_NEAR(ta, last, 1e-12);
      }
      first = false;
      last = tb;
      // Points on the cell's faces (f = 0 and f → 1) round either way: the dilation covers both.
      for (double f : {0.0, 0.1, 0.5, 0.9, 0.999999, 1.0}) {
        const double t = ta + f * (tb - ta);
        const std::array<double, 3> x{o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        EXPECT_LE(tracker.value_at(x), majorant);
        EXPECT_LE(value_at_point(g, x[0], x[1], x[2]), majorant);
      }
      return true;
    });
  }
  EXPECT_GT(segments, 100);  // most rays cross the grid
}

// Several channels (a direction-dependent medium's per-axis grids, docs/render.md §6d) share one
// majorant grid: every cell bounds every channel's point values, and so any weighted sum with
// weights ≥ 0 summing to 1; with one channel it is that channel's own majorant grid.
TEST(MajorantGrid, SeveralChannelsShareOneBoundOverTheirPerVoxelMaximum) {
  const Grid a = varying_grid();
  Grid b(1.0 / 24.0, "other");
  for (int i = -12; i < 12; ++i)
    for (int j = -12; j < 12; ++j) b.set_value(i, j, 11, 2.0f);  // a dense top layer that a lacks
  b.set_origin({0.0, 0.0, 0.0});
  const MajorantGrid m({&a, &b});
  EXPECT_DOUBLE_EQ(m.max_value(), 2.0);
  const MajorantGrid ma(a);
  MajorantTracker tracker({&a, &b}, m);
  Pcg32 rng(9);
  for (int trial = 0; trial < 200; ++trial) {
    std::array<double, 3> o{rng.uniform() * 3 - 1.5, rng.uniform() * 3 - 1.5, rng.uniform() * 3 - 1.5};
    std::array<double, 3> d{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (double& x : d) x /= len;
    tracker.walk(Ray{o, d}, 0.0, 10.0, [&](double ta, double tb, double majorant) {
      for (double f : {0.0, 0.5, 0.999999}) {
        const double t = ta + f * (tb - ta);
        const std::array<double, 3> x{o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        EXPECT_LE(value_at_point(a, x[0], x[1], x[2]), majorant);
        EXPECT_LE(value_at_point(b, x[0], x[1], x[2]), majorant);
      }
      return true;
    });
  }
  EXPECT_GE(m.active_cells(), ma.active_cells());
  // Channels of another voxel size cannot share cells.
  const Grid coarse(1.0 / 12.0, "coarse");
  EXPECT_THROW(MajorantGrid({&a, &coarse}), Error);
}

// Weighted channels are tracked as one grid of the weighted values: weights (1, 0) are channel
// a's own ratio tracking, the same numbers from the same random stream.
TEST(MajorantTracker, WeightOneOnAChannelIsThatChannelsTracking) {
  const Grid a = varying_grid();
  const MajorantGrid m(a);
  MajorantTracker one(a, m);
  MajorantTracker weighted(std::vector<const Grid*>{&a}, m);
  const Ray ray{{-0.2, -0.3, -0.4}, {0.6, 0.64, 0.48}};
  Pcg32 r1(4);
  Pcg32 r2(4);
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(one.ratio_track(ray, 0.0, 2.0, 3.0, r1), weighted.ratio_track(ray, 0.0, 2.0, 3.0, {1.0}, r2));
    EXPECT_EQ(one.delta_track(ray, 0.0, 2.0, 3.0, r1).t, weighted.delta_track(ray, 0.0, 2.0, 3.0, {1.0}, r2).t);
  }
  EXPECT_THROW((void)weighted.ratio_track(ray, 0.0, 2.0, 3.0, {0.5, 0.5}, r2), Error);
}

TEST(MajorantTracker, RaysThatMissCollideNeverAndTransmitFully) {
  const Grid g = varying_grid();
  const MajorantGrid m(g);
  MajorantTracker tracker(g, m);
  Pcg32 rng(1);
  const Ray away{{2.0, 2.0, 2.0}, {1.0, 0.0, 0.0}};
  EXPECT_FALSE(tracker.delta_track(away, 0.0, 100.0, 10.0, rng).collided);
  EXPECT_EQ(tracker.ratio_track(away, 0.0, 100.0, 10.0, rng), 1.0);
  const Ray along_top{{-1.0, 0.5, 0.0}, {1.0, 0.0, 0.0}};  // on the upper face y = 0.5: outside
  EXPECT_FALSE(tracker.delta_track(along_top, 0.0, 100.0, 10.0, rng).collided);
}

// Delta tracking samples the exponential flight of the exact optical depth: the fraction of
// flights that collide before t1 is 1 − e^{−τ(t1)} (binomial standard error), and ratio
// tracking's mean is e^{−τ} (standard error from its sample variance).
TEST(MajorantTracker, DeltaAndRatioTrackingMatchTheExactOpticalDepth) {
  const Grid g = varying_grid();
  const MajorantGrid m(g);
  MajorantTracker tracker(g, m);
  DepthTracker exact(g);
  constexpr double kScale = 6.0;
  const std::vector<Ray> rays{{{-1.0, -0.2, 0.1}, {1.0, 0.0, 0.0}},
                              {{-0.7, -0.6, -0.8}, {0.5, 0.45, 0.74}},
                              {{0.1, 0.2, -1.0}, {0.0, 0.0, 1.0}}};
  for (std::size_t r = 0; r < rays.size(); ++r) {
    Ray ray = rays[r];
    const double len = std::hypot(ray.direction[0], ray.direction[1], ray.direction[2]);
    for (double& x : ray.direction) x /= len;
    const double t1 = 1.6;
    const double tau = exact.optical_depth(ray, 0.0, t1, kScale);
    ASSERT_GT(tau, 0.05);
    Pcg32 rng = stream_for(7, r);
    constexpr int kN = 20000;
    int collided = 0;
    double sum = 0.0;
    double sum2 = 0.0;
    for (int i = 0; i < kN; ++i) {
      const TrackedCollision c = tracker.delta_track(ray, 0.0, t1, kScale, rng);
      if (c.collided) {
        ++collided;
        EXPECT_GE(c.t, 0.0);
        EXPECT_LT(c.t, t1);
        EXPECT_GT(tracker.value_at({ray.origin[0] + c.t * ray.direction[0], ray.origin[1] + c.t * ray.direction[1],
                                    ray.origin[2] + c.t * ray.direction[2]}),
                  0.0);
      }
      const double tr = tracker.ratio_track(ray, 0.0, t1, kScale, rng);
      sum += tr;
      sum2 += tr * tr;
    }
    const double p = 1.0 - std::exp(-tau);
    EXPECT_NEAR(static_cast<double>(collided) / kN, p, 5.0 * std::sqrt(p * (1 - p) / kN)) << "ray " << r;
    const double mean = sum / kN;
    const double se = std::sqrt(std::max(0.0, sum2 / kN - mean * mean) / kN);
    EXPECT_NEAR(mean, std::exp(-tau), 5.0 * se + 1e-12) << "ray " << r;
  }
}

// The optical-depth march stops where the accumulated τ reaches τ*, exactly.
TEST(DepthTracker, MarchStopsWhereTheOpticalDepthIsReached) {
  const Grid g = varying_grid();
  DepthTracker tracker(g);
  const Ray ray{{-0.9, -0.3, -0.2}, {0.8, 0.5, 0.3}};
  Ray unit = ray;
  const double len = std::hypot(ray.direction[0], ray.direction[1], ray.direction[2]);
  for (double& x : unit.direction) x /= len;
  const double total = tracker.optical_depth(unit, 0.0, 5.0, 4.0);
  for (double f : {0.01, 0.3, 0.77, 0.999}) {
    const DepthHit h = tracker.march_to(unit, 0.0, 5.0, 4.0, f * total);
    ASSERT_TRUE(h.reached);
    EXPECT_NEAR(h.tau, f * total, 1e-12);
    EXPECT_NEAR(tracker.optical_depth(unit, 0.0, h.t, 4.0), f * total, 1e-9 * total);
  }
  const DepthHit past = tracker.march_to(unit, 0.0, 5.0, 4.0, 2.0 * total);
  EXPECT_FALSE(past.reached);
  EXPECT_EQ(past.t, 5.0);
  EXPECT_NEAR(past.tau, total, 1e-12);
  EXPECT_NEAR(total, optical_depth(g, unit, 0.0, 5.0, 4.0), 1e-12);
}

// A walked shadow ended by Russian roulette once e^{−τ} < ShadowRoulette::kBelow: exact above
// that, unbiased below (mean e^{−τ} within 5σ, and some walks do end early).
TEST(DepthTracker, RouletteTransmittanceIsExactWhileLargeAndUnbiasedBelow) {
  const Grid g = varying_grid();
  DepthTracker tracker(g);
  Ray ray{{-0.7, -0.6, -0.8}, {0.5, 0.45, 0.74}};
  const double len = std::hypot(ray.direction[0], ray.direction[1], ray.direction[2]);
  for (double& x : ray.direction) x /= len;
  Pcg32 rng = stream_for(11, 0);
  for (const double scale : {0.5, 5.0, 9.0}) {
    const double exact = std::exp(-tracker.optical_depth(ray, 0.0, 1.6, scale));
    if (exact > ShadowRoulette::kBelow) {
      EXPECT_NEAR(tracker.transmittance(ray, 0.0, 1.6, scale, rng), exact, 1e-12 * exact) << scale;
      continue;
    }
    constexpr int kN = 40000;
    double sum = 0.0;
    double sum2 = 0.0;
    int ended = 0;
    for (int i = 0; i < kN; ++i) {
      const double tr = tracker.transmittance(ray, 0.0, 1.6, scale, rng);
      ended += tr == 0.0 ? 1 : 0;
      sum += tr;
      sum2 += tr * tr;
    }
    const double mean = sum / kN;
    const double se = std::sqrt(std::max(0.0, sum2 / kN - mean * mean) / kN);
    EXPECT_GT(ended, 0) << scale;
    EXPECT_NEAR(mean, exact, 5.0 * se + 1e-15) << scale;
  }
}

}  // namespace
}  // namespace weft::volume
