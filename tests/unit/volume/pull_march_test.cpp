// The pull-style march (Tracer::start/next, used by render's local-gamma fields without a
// callback), cached voxel reads (VoxelReader), and the value checks of Grid::load that the
// render media rely on instead of opening the tree themselves.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <openvdb/openvdb.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

/// A sparse random grid with voxels at negative and positive indices, an active 8³ tile and
/// an active 128³ tile, so a march crosses leaves, tiles and empty nodes.
Grid sparse_grid_with_tiles() {
  ensure_openvdb_initialized();
  Grid g(0.37);
  g.set_origin({-1.3, 0.2, 0.9});
  Pcg32 rng(21, 3);
  for (int i = -12; i < 12; ++i)
    for (int j = -12; j < 12; ++j)
      for (int k = -12; k < 12; ++k)
        if (rng.uniform() < 0.3) g.set_value(i, j, k, static_cast<float>(0.1 + 3.0 * rng.uniform()));
  auto& tree = g.impl().grid->tree();
  tree.addTile(1, openvdb::Coord(16, 0, 0), 2.0f, true);
  tree.addTile(2, openvdb::Coord(128, 0, 0), 0.5f, true);
  return g;
}

std::vector<Segment> pulled(Tracer& tracer, const Ray& ray, double t0, double t1) {
  std::vector<Segment> out;
  tracer.start(ray, t0, t1);
  Segment s;
  while (tracer.next(s)) out.push_back(s);
  return out;
}

std::vector<Segment> called_back(const Grid& g, const Ray& ray, double t0, double t1) {
  std::vector<Segment> out;
  march(g, ray, t0, t1, [&](const Segment& s) {
    out.push_back(s);
    return true;
  });
  return out;
}

Ray random_ray(Pcg32& rng, bool axis_aligned) {
  Ray ray;
  for (int a = 0; a < 3; ++a) ray.origin[a] = -6.0 + 12.0 * rng.uniform();
  if (axis_aligned) {
    const auto a = static_cast<std::size_t>(rng.uniform() * 3.0) % 3;
    ray.direction = {0.0, 0.0, 0.0};
    ray.direction[a] = rng.uniform() < 0.5 ? -1.0 : 1.0;
    // On a voxel face: the face convention (upper voxel) must hold for pulled walks too.
    const std::size_t b = (a + 1) % 3;
    ray.origin[b] = -1.3 * (b == 0) + 0.2 * (b == 1) + 0.9 * (b == 2) + 0.37 * std::round(ray.origin[b] / 0.37);
  } else {
    const double z = 1.0 - 2.0 * rng.uniform();
    const double phi = 2.0 * std::numbers::pi * rng.uniform();
    ray.direction = {std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z};
  }
  return ray;
}

TEST(PullMarch, SegmentsEqualTheCallbackMarchAndTileTheRay) {
  const Grid g = sparse_grid_with_tiles();
  Tracer tracer(g);
  Pcg32 rng(5, 9);
  int tiles_seen = 0;
  for (int r = 0; r < 300; ++r) {
    const Ray ray = random_ray(rng, r % 3 == 0);
    const double t0 = rng.uniform() < 0.5 ? 0.0 : 2.0 * rng.uniform();
    const double t1 = t0 + 60.0 * rng.uniform();
    const auto a = pulled(tracer, ray, t0, t1);
    const auto b = called_back(g, ray, t0, t1);
    ASSERT_EQ(a.size(), b.size()) << "ray " << r;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].t0, b[i].t0);
      EXPECT_EQ(a[i].t1, b[i].t1);
      EXPECT_EQ(a[i].value, b[i].value);
      EXPECT_EQ(a[i].voxel, b[i].voxel);
      EXPECT_EQ(a[i].size, b[i].size);
      EXPECT_GT(a[i].t1, a[i].t0);
      if (i > 0) {
        EXPECT_EQ(a[i].t0, a[i - 1].t1) << "gap in ray " << r;
      }
      if (a[i].size > 1) ++tiles_seen;
      if (a[i].size == 1) {
        EXPECT_EQ(a[i].value, g.value(a[i].voxel[0], a[i].voxel[1], a[i].voxel[2]));
      }
    }
    if (!a.empty()) {
      EXPECT_GE(a.front().t0, t0);
      EXPECT_LE(a.back().t1, t1);
    }
  }
  EXPECT_GT(tiles_seen, 0) << "the rays must cross tiles or empty nodes";
}

TEST(PullMarch, StartingAgainAbandonsTheWalkAndMissesGiveNothing) {
  const Grid g = sparse_grid_with_tiles();
  Tracer tracer(g);
  const Ray ray{{-6.0, 0.5, 0.5}, {1.0, 0.2, 0.1}};
  const auto full = pulled(tracer, ray, 0.0, 100.0);
  ASSERT_GT(full.size(), 3U);
  tracer.start(ray, 0.0, 100.0);
  Segment s;
  ASSERT_TRUE(tracer.next(s));
  ASSERT_TRUE(tracer.next(s));
  // A second walk from scratch: the same segments as an uninterrupted one.
  const auto again = pulled(tracer, ray, 0.0, 100.0);
  ASSERT_EQ(again.size(), full.size());
  for (std::size_t i = 0; i < full.size(); ++i) EXPECT_EQ(again[i].t1, full[i].t1);
  // A ray pointing away from the box: no segment, and next keeps returning false.
  tracer.start({{-60.0, 0.0, 0.0}, {-1.0, 0.0, 0.0}}, 0.0, 1e9);
  EXPECT_FALSE(tracer.next(s));
  EXPECT_FALSE(tracer.next(s));
  // Bad rays are refused by start, as by march.
  EXPECT_THROW(tracer.start({{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, 0.0, 1.0), Error);
  EXPECT_THROW(tracer.start(ray, std::nan(""), 1.0), Error);
}

TEST(VoxelReader, ReadsVoxelsAndTilesAndZeroWhereInactive) {
  const Grid g = sparse_grid_with_tiles();
  VoxelReader reader(g);
  Pcg32 rng(8, 2);
  for (int n = 0; n < 2000; ++n) {
    const std::array<int, 3> c{static_cast<int>(rng.uniform() * 30) - 15, static_cast<int>(rng.uniform() * 30) - 15,
                               static_cast<int>(rng.uniform() * 30) - 15};
    EXPECT_EQ(reader.value(c), g.value(c[0], c[1], c[2]));
  }
  EXPECT_EQ(reader.value({17, 3, 5}), 2.0f);   // inside the 8³ tile
  EXPECT_EQ(reader.value({200, 9, 9}), 0.5f);  // inside the 128³ tile
  EXPECT_EQ(reader.value({-4000, 0, 0}), 0.0f);
}

TEST(GridLoad, RefusesNegativeNanAndInfiniteValuesAndTilesNamingTheVoxel) {
  ensure_openvdb_initialized();
  const auto dir = std::filesystem::temp_directory_path();
  struct Case {
    std::string label;
    float value;
    bool tile;
    std::string expect;
  };
  const std::vector<Case> cases{{"negative", -0.5f, false, "(3, 4, 5)"},
                                {"nan", std::numeric_limits<float>::quiet_NaN(), false, "nan"},
                                {"inf", std::numeric_limits<float>::infinity(), false, "inf"},
                                {"negative_tile", -1.0f, true, ">= 0"}};
  for (const auto& c : cases) {
    Grid g(0.1, "mean_concentration");
    g.set_value(0, 0, 0, 0.2f);
    if (c.tile) {
      g.impl().grid->tree().addTile(1, openvdb::Coord(64, 0, 0), c.value, true);
    } else {
      g.set_value(3, 4, 5, c.value);
    }
    const auto path = dir / ("weft_grid_load_" + c.label + ".vdb");
    save_grids({g}, path);
    EXPECT_THAT([&] { (void)Grid::load(path, "mean_concentration"); },
                weft::test::throws_one_line_error_with({path.string(), "mean_concentration", c.expect}))
        << c.label;
    std::filesystem::remove(path);
  }
}

}  // namespace
}  // namespace weft::volume
