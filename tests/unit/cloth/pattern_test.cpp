#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "data_gen/cloth/pattern.h"
#include "weft/core/error.h"

namespace weft::cloth {
namespace {

const std::vector<std::string> kWoven = {"plain", "twill21", "twill22", "twill31", "satin5", "basket"};

ClothSpec woven(const std::string& pattern, int warps, int wefts) {
  ClothSpec spec;
  spec.pattern = pattern;
  spec.warp_count = warps;
  spec.weft_count = wefts;
  spec.warp_yarn = yarn_preset("cotton");
  spec.weft_yarn = yarn_preset("polyester");
  return resolve(spec);
}

// Smallest distance between two polylines (segment–segment, clamped closest points).
double segment_distance(const Point3& p1, const Point3& q1, const Point3& p2, const Point3& q2) {
  const auto sub = [](const Point3& a, const Point3& b) { return Point3{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  const auto dot = [](const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const Point3 d1 = sub(q1, p1), d2 = sub(q2, p2), r = sub(p1, p2);
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r), c = dot(d1, r), b = dot(d1, d2);
  const double denom = a * e - b * b;
  double s = denom > 1e-300 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  Point3 d{};
  for (int k = 0; k < 3; ++k) d[k] = p1[k] + d1[k] * s - p2[k] - d2[k] * t;
  return std::sqrt(dot(d, d));
}

double curve_distance(const Curve& a, const Curve& b) {
  double best = 1e300;
  for (std::size_t i = 1; i < a.points.size(); ++i) {
    for (std::size_t j = 1; j < b.points.size(); ++j) {
      best = std::min(best, segment_distance(a.points[i - 1], a.points[i], b.points[j - 1], b.points[j]));
    }
  }
  return best;
}

TEST(WovenPattern, InterlacingIsPeriodicWithItsRepeat) {
  for (const auto& p : kWoven) {
    const int n = pattern_repeat(p);
    for (int i = -7; i < 13; ++i) {
      for (int j = -7; j < 13; ++j) {
        ASSERT_EQ(warp_over(p, i, j), warp_over(p, i + n, j)) << p;
        ASSERT_EQ(warp_over(p, i, j), warp_over(p, i, j + n)) << p;
      }
    }
  }
}

TEST(WovenPattern, FloatsHaveTheNamedLengths) {
  // Over-runs of one warp within a repeat: plain 1, twill a/b → a over then b under, satin5 →
  // 4 over 1 under, basket 2 over 2 under; and every weft of the repeat is crossed.
  const auto overs = [](const std::string& p, int j) {
    int count = 0;
    for (int i = 0; i < pattern_repeat(p); ++i) count += warp_over(p, i, j) ? 1 : 0;
    return count;
  };
  for (int j = 0; j < 10; ++j) {
    EXPECT_EQ(overs("plain", j), 1);
    EXPECT_EQ(overs("twill21", j), 2);
    EXPECT_EQ(overs("twill22", j), 2);
    EXPECT_EQ(overs("twill31", j), 3);
    EXPECT_EQ(overs("satin5", j), 4);
    EXPECT_EQ(overs("basket", j), 2);
  }
  // Twill lines advance by one weft per warp; satin interlacings are never adjacent.
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < 6; ++i) EXPECT_EQ(warp_over("twill22", i, j), warp_over("twill22", i + 1, j - 1));
    for (int i = 0; i < 5; ++i) {
      if (!warp_over("satin5", i, j)) {
        EXPECT_TRUE(warp_over("satin5", i + 1, j + 1));
        EXPECT_TRUE(warp_over("satin5", i - 1, j + 1));
      }
    }
  }
  EXPECT_THROW(warp_over("stockinette", 0, 0), Error);
}

TEST(WovenPattern, CentrelinesArePeriodicAndPassCrossingsAtPlusMinusCrimp) {
  for (const auto& p : kWoven) {
    const ClothSpec spec = woven(p, 10, 10);
    const int n = pattern_repeat(p);
    for (int j = 0; j < 3; ++j) {
      for (double x = 0.0; x < 2.0; x += 0.0137) {
        ASSERT_NEAR(warp_height(spec, j, x), warp_height(spec, j, x + n * spec.weft_spacing), 1e-12) << p;
        ASSERT_NEAR(warp_height(spec, j, x), warp_height(spec, j + n, x), 1e-12) << p;
        ASSERT_NEAR(weft_height(spec, j, x), weft_height(spec, j + n, x), 1e-12) << p;
      }
      for (int i = 0; i < 10; ++i) {
        const double at = warp_height(spec, j, (i + 0.5) * spec.weft_spacing);
        EXPECT_NEAR(at, warp_over(p, i, j) ? spec.crimp : -spec.crimp, 1e-12);
        EXPECT_NEAR(weft_height(spec, i, (j + 0.5) * spec.warp_spacing), -at, 1e-12);
      }
    }
    const CurveSet set = woven_centerlines(spec);
    EXPECT_EQ(set.curves.size(), 20U);
    EXPECT_EQ(std::count(set.direction.begin(), set.direction.end(), 1), 10);
  }
}

TEST(WovenPattern, YarnsDoNotIntersectAtDefaultSpacing) {
  // Yarn envelopes (radius r_env around each centreline) must not overlap: any two different
  // centrelines stay at least r_a + r_b apart.
  for (const auto& p : kWoven) {
    const ClothSpec spec = woven(p, 5, 5);
    const CurveSet set = woven_centerlines(spec);
    const double rw = yarn_envelope_radius(spec.warp_yarn);
    const double rf = yarn_envelope_radius(spec.weft_yarn);
    for (std::size_t a = 0; a < set.curves.size(); ++a) {
      for (std::size_t b = a + 1; b < set.curves.size(); ++b) {
        const double ra = set.direction[a] == 0 ? rw : rf;
        const double rb = set.direction[b] == 0 ? rw : rf;
        ASSERT_GE(curve_distance(set.curves[a], set.curves[b]), ra + rb) << p << " yarns " << a << " and " << b;
      }
    }
  }
}

TEST(KnitPattern, CoursesInterlockWithoutIntersecting) {
  ClothSpec spec;
  spec.pattern = "stockinette";
  spec.warp_count = 3;
  spec.weft_count = 3;
  spec = resolve(spec);
  const CurveSet set = knit_centerlines(spec);
  ASSERT_EQ(set.curves.size(), 3U);
  const double r = yarn_envelope_radius(spec.warp_yarn);
  EXPECT_GE(curve_distance(set.curves[0], set.curves[1]), 2.0 * r);
  EXPECT_GE(curve_distance(set.curves[1], set.curves[2]), 2.0 * r);
  // Loops overlap the next course (interlock): the loop head rises above the next course's base.
  double top0 = -1e300, base1 = 1e300;
  for (const auto& q : set.curves[0].points) top0 = std::max(top0, q[1]);
  for (const auto& q : set.curves[1].points) base1 = std::min(base1, q[1]);
  EXPECT_GT(top0, base1 + 2.0 * r);
  // Within a course, parts of the yarn more than half a stitch apart along it stay 2r apart.
  const auto& c = set.curves[0].points;
  const std::size_t per_stitch = (c.size() - 1) / 3;
  for (std::size_t i = 0; i < c.size(); i += 2) {
    for (std::size_t j = i + per_stitch * 2 / 3; j < c.size(); j += 2) {
      const double d = std::hypot(c[i][0] - c[j][0], c[i][1] - c[j][1], c[i][2] - c[j][2]);
      ASSERT_GE(d, 2.0 * r) << i << " " << j;
    }
  }
  // Periodic: stitch k+1 is stitch k moved by one wale; course r+1 is course r moved by one course.
  for (std::size_t i = 0; i + per_stitch < c.size(); i += 7) {
    EXPECT_NEAR(c[i + per_stitch][0], c[i][0] + spec.weft_spacing, 1e-9);
    EXPECT_NEAR(c[i + per_stitch][1], c[i][1], 1e-9);
    EXPECT_NEAR(set.curves[1].points[i][1], c[i][1] + spec.warp_spacing, 1e-9);
  }
}

TEST(ClothSpecTest, ResolveIsIdempotentAndValidateNamesParameters) {
  const ClothSpec a = woven("twill22", 4, 4);
  const ClothSpec b = resolve(a);
  EXPECT_EQ(a.warp_spacing, b.warp_spacing);
  EXPECT_EQ(a.crimp, b.crimp);
  const auto message = [](ClothSpec s) {
    try {
      validate(s);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  ClothSpec s = a;
  s.warp_spacing = -1.0;
  EXPECT_NE(message(s).find("warp_spacing"), std::string::npos);
  s = a;
  s.voxel_size = 0.0;
  EXPECT_NE(message(s).find("voxel_size"), std::string::npos);
  s = a;
  s.crimp = std::nan("");
  EXPECT_NE(message(s).find("crimp"), std::string::npos);
  s = a;
  s.pattern = "lace";
  EXPECT_NE(message(s).find("lace"), std::string::npos);
  s = a;
  s.weft_yarn.fiber_pitch = -2.0;
  EXPECT_NE(message(s).find("weft_yarn.fiber_pitch"), std::string::npos);
}

}  // namespace
}  // namespace weft::cloth
