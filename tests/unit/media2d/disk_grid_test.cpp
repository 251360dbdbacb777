// Ray–disk intersection through the periodic uniform grid, checked against brute force.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <utility>

#include "data_gen/media2d/disk_grid.h"
#include "weft/core/error.h"

namespace weft::media2d {
namespace {

Medium random_medium(std::size_t n, double r, std::uint64_t seed) {
  Medium m;
  m.radius = r;
  Pcg32 rng(seed);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = rng.uniform();
    m.centers.push_back({x, rng.uniform()});
  }
  // Disks straddling the seams and the corner, where images matter.
  m.centers.push_back({0.0005, 0.5});
  m.centers.push_back({0.9995, 0.25});
  m.centers.push_back({0.3, 0.0002});
  m.centers.push_back({0.9999, 0.9999});
  return m;
}

TEST(RayDisk, EntryDistanceIsExactForTinyRadiusFarAway) {
  const double r = 1e-5;
  const Point2 o{0.0, 0.0};
  const Point2 d{1.0, 0.0};
  for (const double b : {0.0, 0.3e-5, 0.99e-5}) {
    const double t = ray_disk_entry(o, d, {0.7, b}, r);
    EXPECT_NEAR(t, 0.7 - std::sqrt(r * r - b * b), 1e-15) << b;
  }
  EXPECT_EQ(ray_disk_entry(o, d, {0.7, 1.01e-5}, r), std::numeric_limits<double>::infinity());
  EXPECT_EQ(ray_disk_entry(o, d, {-0.7, 0.0}, r), std::numeric_limits<double>::infinity());
  EXPECT_EQ(ray_disk_entry(o, d, {0.5e-5, 0.0}, r), 0.0);  // origin inside
}

struct RayCase {
  const char* what;
  Point2 origin;
  Point2 direction;
  double t_max;
};

TEST(DiskGrid, MatchesBruteForceOnHardRays) {
  const Medium m = random_medium(300, 0.004, 21);
  const DiskGrid grid(m, 1.5);
  const std::vector<RayCase> table{
      {"+x axis", {0.1, 0.5}, {1.0, 0.0}, 3.0},
      {"-x axis across seam", {0.1, 0.5}, {-1.0, 0.0}, 3.0},
      {"+y axis", {0.3, 0.9}, {0.0, 1.0}, 3.0},
      {"-y axis", {0.3, 0.1}, {0.0, -1.0}, 3.0},
      {"diagonal through corner", {0.9, 0.9}, {1.0, 1.0}, 4.0},
      {"origin outside the square", {-2.3, 5.7}, {0.3, -0.8}, 5.0},
      {"on a cell wall", {0.5, 0.5}, {1.0, 1e-12}, 2.0},
      {"long ray, many wraps", {0.2, 0.7}, {0.1234, 0.987}, 12.0},
  };
  for (const auto& c : table) {
    const Hit a = grid.first_hit(c.origin, c.direction, c.t_max);
    const Hit b = brute_force_first_hit(m, c.origin, c.direction, c.t_max);
    ASSERT_EQ(a.disk, b.disk) << c.what;
    if (b.found()) {
      EXPECT_NEAR(a.t, b.t, 1e-12) << c.what;
    }
  }
}

TEST(DiskGrid, MatchesBruteForceOnRandomRays) {
  const Medium m = random_medium(400, 0.003, 22);
  const DiskGrid grid(m);
  Pcg32 rng(23);
  std::size_t found = 0;
  for (int i = 0; i < 3000; ++i) {
    const Point2 o{3.0 * rng.uniform() - 1.0, 3.0 * rng.uniform() - 1.0};
    const double phi = 2.0 * std::numbers::pi * rng.uniform();
    const double t_max = 4.0 * rng.uniform();
    const Hit a = grid.first_hit(o, {std::cos(phi), std::sin(phi)}, t_max);
    const Hit b = brute_force_first_hit(m, o, {std::cos(phi), std::sin(phi)}, t_max);
    ASSERT_EQ(a.disk, b.disk) << i;
    if (b.found()) {
      ++found;
      ASSERT_NEAR(a.t, b.t, 1e-12) << i;
    }
  }
  EXPECT_GT(found, 1000U);  // the table exercises hits, not only misses
}

TEST(DiskGrid, RayFromAScattererSkipsOnlyItsOwnImage) {
  Medium m;
  m.radius = 0.01;
  m.centers = {{0.5, 0.5}, {0.8, 0.5}};
  const DiskGrid grid(m);
  const Point2 start{0.51, 0.5};  // on disk 0's surface, leaving along +x
  const Hit next = grid.first_hit(start, {1.0, 0.0}, 5.0, 0);
  ASSERT_EQ(next.disk, 1U);
  EXPECT_NEAR(next.t, 0.28, 1e-12);
  // Leaving along −x, the next disk is disk 1's image at x = −0.2 (after 0.7) before disk 0's own
  // next image at x = −0.5.
  const Hit back = grid.first_hit(start, {-1.0, 0.0}, 5.0, 0);
  ASSERT_EQ(back.disk, 1U);
  EXPECT_NEAR(back.t, 0.51 + 0.2 - 0.01, 1e-12);
  // Alone in the square, a scatterer's ray meets its own next image one domain length later.
  Medium single;
  single.radius = 0.01;
  single.centers = {{0.5, 0.5}};
  const DiskGrid g1(single);
  const Hit self = g1.first_hit(start, {1.0, 0.0}, 5.0, 0);
  ASSERT_EQ(self.disk, 0U);
  EXPECT_NEAR(self.t, 0.98, 1e-12);
  EXPECT_EQ(brute_force_first_hit(single, start, {1.0, 0.0}, 5.0, 0).t, self.t);
}

TEST(DiskGrid, InsideAnyFindsDisksAcrossTheSeam) {
  Medium m;
  m.radius = 0.01;
  m.centers = {{0.999, 0.5}};
  const DiskGrid grid(m);
  EXPECT_TRUE(grid.inside_any({0.005, 0.5}));
  EXPECT_TRUE(grid.inside_any({0.995, 0.5}));
  EXPECT_FALSE(grid.inside_any({0.02, 0.5}));
}

TEST(DiskGrid, RejectsZeroDirection) {
  EXPECT_THROW((void)DiskGrid(random_medium(10, 0.01, 1)).first_hit({0, 0}, {0, 0}, 1.0), Error);
}

// An axis-aligned ray repeats its path every domain length (disk_grid.h): in a row the disks leave
// empty it never hits, and its walk must stop after one length, not at t_max. The old walk took
// one step per domain length here (a single grid cell): 1e8 steps a ray for this t_max, seconds in all.
TEST(DiskGrid, AxisRayInAnEmptyRowStopsAfterOneDomainLength) {
  Medium m;
  m.radius = 0.01;
  m.centers = {{0.3, 0.2}, {0.7, 0.8}};
  const DiskGrid grid(m);
  ASSERT_EQ(grid.cells_per_side(), 1U);
  const auto start = std::chrono::steady_clock::now();
  for (const Point2 d : {Point2{1.0, 0.0}, Point2{-1.0, 0.0}, Point2{0.0, 1.0}, Point2{0.0, -1.0}}) {
    EXPECT_FALSE(grid.first_hit({0.1, 0.5}, d, 1e8).found()) << d.x << "," << d.y;  // row y = 0.5 is empty
    EXPECT_FALSE(grid.first_hit({0.5, 0.5}, d, 1e8).found()) << d.x << "," << d.y;  // column x = 0.5 too
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 1.0);
  // Rows and columns that do hold a disk still find it, across the seam, as the brute force does.
  for (const auto& [o, d] :
       {std::pair{Point2{0.9, 0.2}, Point2{1.0, 0.0}}, std::pair{Point2{0.7, 0.1}, Point2{0.0, -1.0}},
        std::pair{Point2{0.305, 0.5}, Point2{0.0, 1.0}}}) {
    const Hit fast = grid.first_hit(o, d, 1e10);
    const Hit slow = brute_force_first_hit(m, o, d, 2.0);
    ASSERT_TRUE(fast.found());
    EXPECT_EQ(fast.disk, slow.disk);
    EXPECT_DOUBLE_EQ(fast.t, slow.t);
  }
  // A scatterer's ray along an axis meets the next image of its own disk one length on.
  const Hit own = grid.first_hit({0.31, 0.2}, {1.0, 0.0}, 1e10, 0);
  ASSERT_TRUE(own.found());
  EXPECT_EQ(own.disk, 0U);
  EXPECT_NEAR(own.t, 1.0 - 0.02, 1e-12);
}

}  // namespace
}  // namespace weft::media2d
