// Exactness of the Amanatides–Woo traversal: faces, edges, corners, zero and −0.0 direction
// components, misses, active tiles, and agreement with an independent fine-step integration.
#include <gtest/gtest.h>

#include <openvdb/openvdb.h>
#include <cmath>
#include <map>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

/// A dense block nx×ny×nz of active voxels with distinct values, voxel size h, origin o.
Grid dense_grid(int nx, int ny, int nz, double h, std::array<double, 3> o) {
  Grid g(h);
  g.set_origin(o);
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      for (int k = 0; k < nz; ++k) g.set_value(i, j, k, static_cast<float>(1 + i + 10 * j + 100 * k));
    }
  }
  return g;
}

using Key = std::array<int, 3>;

std::map<Key, int> visits(const Grid& g, const Ray& ray, double* length) {
  std::map<Key, int> seen;
  *length = 0.0;
  march(g, ray, 0.0, 1e9, [&](const Segment& s) {
    EXPECT_GT(s.t1, s.t0);
    EXPECT_EQ(s.size, 1);
    ++seen[s.voxel];
    *length += s.t1 - s.t0;
    EXPECT_EQ(s.value, g.value(s.voxel[0], s.voxel[1], s.voxel[2]));
    return true;
  });
  return seen;
}

TEST(Dda, AxisAlignedRayOnVoxelFaceVisitsEachVoxelOnce) {
  const double h = 0.25;
  const std::array<double, 3> o{-1.0, 0.5, 2.0};
  const std::array<int, 3> n{6, 5, 4};
  const Grid g = dense_grid(n[0], n[1], n[2], h, o);
  // Transverse positions: voxel centres, faces, edges and corners (in voxel units from origin).
  const std::vector<std::pair<double, double>> spots{{2.5, 1.5}, {2.0, 1.5}, {2.5, 1.0},
                                                     {2.0, 1.0}, {0.0, 0.0}, {1.0, 3.0}};
  for (int axis = 0; axis < 3; ++axis) {
    const int ua = (axis + 1) % 3;
    const int va = (axis + 2) % 3;
    for (double sense : {1.0, -1.0}) {
      for (const auto& [pu, pv] : spots) {
        if (pu >= n[ua] || pv >= n[va]) continue;
        for (bool start_on_face : {true, false}) {
          Ray ray;
          ray.origin[ua] = o[ua] + pu * h;
          ray.origin[va] = o[va] + pv * h;
          const double face = sense > 0 ? o[axis] : o[axis] + n[axis] * h;
          ray.origin[axis] = start_on_face ? face : face - sense * 3.0 * h;
          ray.direction = {-0.0, -0.0, -0.0};  // zero components are −0.0 on purpose
          ray.direction[axis] = sense;
          double length = 0.0;
          const auto seen = visits(g, ray, &length);
          ASSERT_EQ(seen.size(), static_cast<std::size_t>(n[axis])) << "axis " << axis << " sense " << sense;
          for (const auto& [key, count] : seen) {
            EXPECT_EQ(count, 1);
            // The half-open convention: a ray on a face belongs to the voxel above it.
            EXPECT_EQ(key[ua], static_cast<int>(std::floor(pu)));
            EXPECT_EQ(key[va], static_cast<int>(std::floor(pv)));
          }
          EXPECT_NEAR(length, n[axis] * h, 1e-12);
        }
      }
    }
  }
}

TEST(Dda, RayAlongUpperBoundaryFaceMissesTheGrid) {
  const Grid g = dense_grid(3, 3, 3, 1.0, {0, 0, 0});
  Ray ray;
  ray.origin = {3.0, 1.5, -1.0};  // x on the box's upper face: outside by the half-open rule
  ray.direction = {0.0, 0.0, 1.0};
  int calls = 0;
  march(g, ray, 0.0, 100.0, [&](const Segment&) { return ++calls > 0; });
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(optical_depth(g, ray, 0.0, 100.0), 0.0);
}

TEST(Dda, DiagonalRayThroughCornersSkipsZeroLengthSegments) {
  const Grid g = dense_grid(4, 4, 4, 1.0, {0, 0, 0});
  Ray ray;
  ray.origin = {0.0, 0.0, 0.0};
  ray.direction = {1.0, 1.0, 1.0};
  double length = 0.0;
  const auto seen = visits(g, ray, &length);
  ASSERT_EQ(seen.size(), 4U);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(seen.count({i, i, i}), 1U);
  EXPECT_NEAR(length, 4.0 * std::sqrt(3.0), 1e-12);
}

TEST(Dda, RaysThatMissOrPointAwayGiveNoSegments) {
  const Grid g = dense_grid(3, 3, 3, 1.0, {0, 0, 0});
  const std::vector<Ray> misses{
      {{-1.0, 5.0, 1.5}, {1.0, 0.0, 0.0}},   // passes beside the box
      {{-1.0, 1.5, 1.5}, {-1.0, 0.0, 0.0}},  // points away
      {{5.0, 5.0, 5.0}, {1.0, 1.0, 1.0}},    // diagonal, away
  };
  for (const auto& ray : misses) {
    EXPECT_FALSE(intersect_active_box(g, ray).hit);
    EXPECT_EQ(optical_depth(g, ray, 0.0, 1e9), 0.0);
  }
}

TEST(Dda, RejectsDegenerateRays) {
  const Grid g = dense_grid(2, 2, 2, 1.0, {0, 0, 0});
  EXPECT_THROW((void)optical_depth(g, Ray{{0, 0, 0}, {0.0, -0.0, 0.0}}, 0.0, 1.0), Error);
  EXPECT_THROW((void)optical_depth(g, Ray{{0, 0, 0}, {NAN, 0.0, 1.0}}, 0.0, 1.0), Error);
  EXPECT_THROW((void)optical_depth(g, Ray{{INFINITY, 0, 0}, {0.0, 0.0, 1.0}}, 0.0, 1.0), Error);
}

TEST(Dda, EmptyGridGivesZeroDepth) {
  const Grid g(0.5);
  EXPECT_EQ(optical_depth(g, Ray{{0, 0, 0}, {0.0, 0.0, 1.0}}, 0.0, 10.0), 0.0);
}

/// Independent reference: midpoint rule with a fine step, locating voxels from the documented
/// convention (voxel i covers [origin + h·i, origin + h·(i+1))) and Grid::value only.
double brute_force_depth(const Grid& g, const Ray& ray, double t1, std::size_t steps) {
  const auto o = g.origin();
  const double h = g.voxel_size();
  const double len = std::sqrt(ray.direction[0] * ray.direction[0] + ray.direction[1] * ray.direction[1] +
                               ray.direction[2] * ray.direction[2]);
  const double dt = t1 / static_cast<double>(steps);
  double tau = 0.0;
  for (std::size_t s = 0; s < steps; ++s) {
    const double t = (static_cast<double>(s) + 0.5) * dt;
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      const double p = ray.origin[a] + t * ray.direction[a] / len;
      idx[a] = static_cast<int>(std::floor((p - o[a]) / h));
    }
    tau += dt * g.value(idx[0], idx[1], idx[2]);
  }
  return tau;
}

TEST(Dda, OpticalDepthMatchesFineStepIntegrationForRandomRays) {
  const double h = 0.37;
  Grid g(h);
  g.set_origin({-1.3, 0.2, 0.9});
  Pcg32 rng(7, 1);
  const int n = 12;
  float vmax = 0.0f;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        if (rng.uniform() < 0.4) {
          const auto v = static_cast<float>(rng.uniform() * 3.0);
          g.set_value(i - 3, j + 2, k - 5, v);
          vmax = std::max(vmax, v);
        }
      }
    }
  }
  const auto o = g.origin();
  const IndexBox box = g.active_bbox();
  for (int r = 0; r < 40; ++r) {
    Ray ray;
    for (int a = 0; a < 3; ++a) {
      // Origins anywhere in (and around) the box; directions uniform on the sphere.
      const double lo = o[a] + h * (box.min[a] - 2);
      const double hi = o[a] + h * (box.max[a] + 3);
      ray.origin[a] = lo + (hi - lo) * rng.uniform();
    }
    const double z = 1.0 - 2.0 * rng.uniform();
    const double phi = 2.0 * M_PI * rng.uniform();
    ray.direction = {std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z};
    const double t1 = 3.0 * n * h;
    const std::size_t steps = 400000;
    const double exact = optical_depth(g, ray, 0.0, t1);
    const double brute = brute_force_depth(g, ray, t1, steps);
    // The midpoint rule errs by at most one step × μmax at each of the ≤ 3·(n+5)+1 voxel
    // boundaries a ray can cross inside the box.
    const double bound = (3.0 * (n + 5) + 1) * (t1 / static_cast<double>(steps)) * vmax;
    EXPECT_NEAR(exact, brute, bound) << "ray " << r;
  }
}

TEST(Dda, ProfileIsCumulativeOpticalDepth) {
  const Grid g = dense_grid(5, 4, 3, 0.5, {0.1, 0.2, 0.3});
  const Ray ray{{-0.3, 0.4, 0.55}, {1.0, 0.3, 0.2}};
  const std::vector<double> depths{0.0, 0.1, 0.5, 0.77, 1.2, 2.0, 3.5, 9.0};
  const auto tau = optical_depth_profile(g, ray, depths, 2.0);
  for (std::size_t k = 0; k < depths.size(); ++k) {
    EXPECT_NEAR(tau[k], optical_depth(g, ray, 0.0, depths[k], 2.0), 1e-12 * (1 + tau[k]));
  }
}

TEST(Dda, ActiveTilesAreOneSegmentEach) {
  ensure_openvdb_initialized();
  Grid g(1.0);
  // An 8³ block filled as one tile at the leaf's parent, and a 128³ tile above it.
  auto& tree = g.impl().grid->tree();
  tree.addTile(1, openvdb::Coord(0, 0, 0), 2.0f, true);
  tree.addTile(2, openvdb::Coord(128, 0, 0), 0.5f, true);
  Ray ray;
  ray.origin = {-5.0, 3.25, 3.75};
  ray.direction = {1.0, 0.0, 0.0};
  std::vector<Segment> segs;
  march(g, ray, 0.0, 1e4, [&](const Segment& s) {
    segs.push_back(s);
    return true;
  });
  double tau = 0.0;
  int tile8 = 0;
  int tile128 = 0;
  for (const auto& s : segs) {
    tau += (s.t1 - s.t0) * s.value;
    if (s.value == 2.0f) {
      EXPECT_EQ(s.size, 8);
      ++tile8;
    }
    if (s.value == 0.5f) {
      EXPECT_EQ(s.size, 128);
      ++tile128;
    }
  }
  EXPECT_EQ(tile8, 1);
  EXPECT_EQ(tile128, 1);
  EXPECT_NEAR(tau, 8 * 2.0 + 128 * 0.5, 1e-9);
  // Segments tile the clipped interval without gaps.
  for (std::size_t i = 1; i < segs.size(); ++i) EXPECT_EQ(segs[i].t0, segs[i - 1].t1);
}

}  // namespace
}  // namespace weft::volume
