// Exact ray–capsule intervals against hand-derived chords, and the index against a brute-force
// loop over every capsule.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/fibres/capsule_index.h"

namespace weft::fibres {
namespace {

TEST(RayCapsule, ChordsOfCylinderSphereAndAxis) {
  Interval iv{};
  // Across the cylinder at distance y from the axis: chord 2√(r² − y²), centred on the axis.
  ASSERT_TRUE(ray_capsule({0.3, 0.1, -5.0}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0}, 0.25, iv));
  EXPECT_NEAR(iv[1] - iv[0], 2.0 * std::sqrt(0.25 * 0.25 - 0.01), 1e-12);
  EXPECT_NEAR(0.5 * (iv[0] + iv[1]), 5.0, 1e-12);
  // Along the axis: the segment plus both hemispherical caps.
  ASSERT_TRUE(ray_capsule({-3.0, 0.0, 0.0}, {1, 0, 0}, {0, 0, 0}, {1, 0, 0}, 0.25, iv));
  EXPECT_NEAR(iv[0], 2.75, 1e-12);
  EXPECT_NEAR(iv[1], 4.25, 1e-12);
  // Past the end of the segment, through the end sphere only.
  ASSERT_TRUE(ray_capsule({1.1, 0.0, -5.0}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0}, 0.25, iv));
  EXPECT_NEAR(iv[1] - iv[0], 2.0 * std::sqrt(0.25 * 0.25 - 0.01), 1e-12);
  // Misses: beside the cylinder, beyond the cap.
  EXPECT_FALSE(ray_capsule({0.5, 0.26, -5.0}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0}, 0.25, iv));
  EXPECT_FALSE(ray_capsule({1.26, 0.0, -5.0}, {0, 0, 1}, {0, 0, 0}, {1, 0, 0}, 0.25, iv));
  // A degenerate segment is a sphere.
  ASSERT_TRUE(ray_capsule({0.0, 0.0, -5.0}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, 0.5, iv));
  EXPECT_NEAR(iv[0], 5.5, 1e-12);
  EXPECT_NEAR(iv[1], 6.5, 1e-12);
}

TEST(RayCapsule, ObliqueChordMatchesPointSampling) {
  // The chord of an oblique ray, checked by the distance of sample points to the segment.
  const Point3 a{0.1, -0.2, 0.05};
  const Point3 b{0.7, 0.4, -0.1};
  const double r = 0.15;
  const double s = 1.0 / std::sqrt(3.0);
  const Point3 d{s, s, s};
  // Through a point 0.03 from the segment's middle (0.4, 0.1, −0.025), starting 2 before it.
  const Point3 o{0.43 - 2 * s, 0.1 - 2 * s, -0.025 - 2 * s};
  Interval iv{};
  ASSERT_TRUE(ray_capsule(o, d, a, b, r, iv));
  const auto dist = [&](double t) {
    const Point3 p{o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    const Point3 ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double u = std::clamp(((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) /
                                    (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]),
                                0.0, 1.0);
    return std::hypot(p[0] - a[0] - u * ab[0], p[1] - a[1] - u * ab[1], p[2] - a[2] - u * ab[2]);
  };
  EXPECT_NEAR(dist(iv[0]), r, 1e-12);
  EXPECT_NEAR(dist(iv[1]), r, 1e-12);
  EXPECT_LT(dist(0.5 * (iv[0] + iv[1])), r);
}

TEST(CapsuleIndex, SameIntervalsAsEveryCapsule) {
  FibreSet fibres;
  Pcg32 rng = stream_for(7, 0);
  for (int f = 0; f < 300; ++f) {
    std::vector<Point3> poly;
    Point3 p{rng.uniform(), rng.uniform(), rng.uniform()};
    for (int k = 0; k < 5; ++k) {
      poly.push_back(p);
      for (double& c : p) c += 0.1 * (rng.uniform() - 0.5);
    }
    fibres.add(poly, 0.005 + 0.01 * rng.uniform());
  }
  const CapsuleIndex index(fibres);
  EXPECT_EQ(index.capsule_count(), 1200U);
  for (int q = 0; q < 200; ++q) {
    const Point3 o{rng.uniform(), rng.uniform(), -0.5};
    const double s = 1.0 / std::sqrt(1.0 + 0.09 + 0.04);
    const Point3 d{0.3 * s, -0.2 * s, s};
    std::vector<Interval> got;
    index.intersect(o, d, 0.0, 3.0, got);
    std::vector<Interval> want;
    for (std::size_t f = 0; f < fibres.size(); ++f) {
      for (std::uint64_t i = fibres.offsets[f] + 1; i < fibres.offsets[f + 1]; ++i) {
        Interval iv{};
        if (ray_capsule(o, d, fibres.points[i - 1], fibres.points[i], fibres.radius[f], iv) && iv[1] >= 0.0 &&
            iv[0] <= 3.0)
          want.push_back({std::max(iv[0], 0.0), std::min(iv[1], 3.0)});
      }
    }
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    EXPECT_EQ(got, want) << "ray " << q;
  }
}

}  // namespace
}  // namespace weft::fibres
