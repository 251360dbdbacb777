// Geometry::clearance and lone_convex against Embree's own answers (docs/render.md §1, "Queries a
// path skips"): the integrator skips a closest-hit query on their word, so a bound above the
// BVH's hit distance, or a convex exit that hits something, would change the path.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/render/geometry.h"
#include "weft/render/scene.h"

namespace weft::render {
namespace {

ShapeDesc box(const Vec3& lo, const Vec3& hi) {
  ShapeDesc s;
  s.kind = ShapeKind::box;
  s.min = lo;
  s.max = hi;
  return s;
}

Vec3 random_direction(Pcg32& rng) {
  const double z = 1.0 - 2.0 * rng.uniform();
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = 2.0 * 3.141592653589793 * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Points in and around every shape, many of them within 1e-6 of a face, and directions both
/// random and grazing (one component 0 or tiny): the clearance never exceeds Embree's hit.
void expect_clearance_below_hits(const SceneDesc& scene, const Vec3& lo, const Vec3& hi, int* skipped) {
  const Geometry g(scene, {}, {});
  Pcg32 rng(7, 11);
  for (int i = 0; i < 200000; ++i) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = lo[k] - 0.2 + (hi[k] - lo[k] + 0.4) * rng.uniform();
    if (i % 3 == 0) {
      const int k = static_cast<int>(rng.uniform() * 3.0) % 3;
      p[k] = (rng.uniform() < 0.5 ? lo[k] : hi[k]) + (rng.uniform() - 0.5) * 2e-6;
    }
    Vec3 d = random_direction(rng);
    if (i % 5 == 0) d[static_cast<int>(rng.uniform() * 3.0) % 3] = (i % 10 == 0) ? 0.0 : 1e-7;
    d.normalize();
    const double c = g.clearance(p, d);
    ASSERT_GE(c, 0.0);
    const auto hit = g.intersect(p, d, 0.0, std::numeric_limits<double>::infinity());
    if (hit) {
      ASSERT_LE(c, hit->t) << "p " << p.transpose() << " d " << d.transpose();
    }
    if (c > 0.0) ++*skipped;
  }
}

TEST(Clearance, NeverBeyondTheBvhHitDistance) {
  SceneDesc one;
  one.shapes = {box({-0.5, 0, -0.5}, {0.5, 1, 0.5})};
  int skipped = 0;
  expect_clearance_below_hits(one, {-0.5, 0, -0.5}, {0.5, 1, 0.5}, &skipped);
  EXPECT_GT(skipped, 50000);  // the bound is useful, not 0 everywhere

  SceneDesc several;
  several.shapes = {box({-0.5, 0, -0.5}, {0.5, 1, 0.5}), box({0.6, 0, 0}, {1.0, 0.3, 0.4})};
  ShapeDesc sphere;
  sphere.center = {0, 1.5, 0};
  sphere.radius = 0.3;
  ShapeDesc rect;
  rect.kind = ShapeKind::rectangle;
  rect.corner = {-1, -0.1, -1};
  rect.edge_u = {2, 0, 0};
  rect.edge_v = {0, 0, 2};
  several.shapes.push_back(sphere);
  several.shapes.push_back(rect);
  skipped = 0;
  expect_clearance_below_hits(several, {-1, -0.1, -1}, {1, 1.8, 1}, &skipped);
  EXPECT_GT(skipped, 20000);
}

TEST(Clearance, LoneConvexShapeIsNotHitAfterLeavingIt) {
  SceneDesc scene;
  scene.shapes = {box({-0.5, 0, -0.5}, {0.5, 1, 0.5})};
  const Geometry g(scene, {}, {});
  ASSERT_TRUE(g.lone_convex());
  Pcg32 rng(3, 5);
  for (int i = 0; i < 100000; ++i) {
    Vec3 p(rng.uniform() - 0.5, rng.uniform(), rng.uniform() - 0.5);
    const Vec3 d = random_direction(rng);
    const auto exit = g.intersect(p, d, 0.0, std::numeric_limits<double>::infinity());
    ASSERT_TRUE(exit.has_value());
    // The integrator's offset along the outward normal.
    const double scale = g.spawn_offset(exit->p, exit->shape);
    const Vec3 out = exit->p + (exit->n.dot(d) > 0.0 ? scale : -scale) * exit->n;
    ASSERT_FALSE(g.intersect(out, d, 0.0, std::numeric_limits<double>::infinity()).has_value());
  }
  SceneDesc two;
  two.shapes = {box({-0.5, 0, -0.5}, {0.5, 1, 0.5}), box({1, 0, 0}, {2, 1, 1})};
  EXPECT_FALSE(Geometry(two, {}, {}).lone_convex());
}

/// `scene` with kMaxAnalyticShapes boxes of 10⁻³ added far from it (50 away, below): more shapes
/// than the closed form takes, so Embree answers every query, and too small and far for a test's
/// rays to meet (about 10⁻⁹ of the directions); the scene's own shapes keep their indices.
SceneDesc with_embree(SceneDesc scene) {
  for (std::size_t i = 0; i < Geometry::kMaxAnalyticShapes; ++i) {
    const double x = 2.0 * static_cast<double>(i);
    scene.shapes.push_back(box({x, -50, 0}, {x + 1e-3, -50 + 1e-3, 1e-3}));
  }
  return scene;
}

SceneDesc boxes_sphere_and_rectangles() {
  SceneDesc scene;
  scene.shapes = {box({-0.5, 0, -0.5}, {0.5, 1, 0.5}), box({0.6, 0, 0}, {1.0, 0.3, 0.4})};
  ShapeDesc sphere;
  sphere.center = {0, 1.5, 0};
  sphere.radius = 0.3;
  scene.shapes.push_back(sphere);
  ShapeDesc floor;  // below everything, facing up
  floor.kind = ShapeKind::rectangle;
  floor.corner = {-1, -0.1, -1};
  floor.edge_u = {0, 0, 2};
  floor.edge_v = {2, 0, 0};
  scene.shapes.push_back(floor);
  ShapeDesc panel;  // a tilted parallelogram whose edges are not orthogonal, through the big box
  panel.kind = ShapeKind::rectangle;
  panel.corner = {-0.8, 0.2, -0.3};
  panel.edge_u = {1.2, 0.3, 0.1};
  panel.edge_v = {0.4, 0.9, 0.7};
  scene.shapes.push_back(panel);
  return scene;
}

// docs/render.md §1, "Queries a path skips" (3): a scene of a few boxes, spheres and rectangles is
// intersected in closed form, in double precision. Against Embree on the same shapes (forced by
// shapes added far away): the same shape, the same normal, the distance within Embree's float
// rounding, the same occlusion, for rays from inside, outside and between the shapes.
TEST(Analytic, TheSameHitsAsEmbreeOnTheSameShapes) {
  const SceneDesc scene = boxes_sphere_and_rectangles();
  const Geometry closed(scene, {}, {});
  const Geometry bvh(with_embree(scene), {}, {});
  ASSERT_TRUE(closed.analytic());
  ASSERT_FALSE(bvh.analytic());
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Pcg32 rng(17, 3);
  std::vector<int> hits(scene.shapes.size(), 0);
  int differ = 0;
  constexpr int kRays = 100000;
  for (int i = 0; i < kRays; ++i) {
    Vec3 p(-1.2 + 2.6 * rng.uniform(), -0.3 + 2.3 * rng.uniform(), -1.2 + 2.4 * rng.uniform());
    Vec3 d = random_direction(rng);
    if (i % 7 == 0) d[static_cast<int>(rng.uniform() * 3.0) % 3] = 0.0;  // parallel to faces
    d.normalize();
    const double tmax = rng.uniform() < 0.5 ? kInf : 3.0 * rng.uniform();
    const auto a = closed.intersect(p, d, 0.0, tmax);
    const auto b = bvh.intersect(p, d, 0.0, tmax);
    // Float rounding decides rays within ~1e-6 of an edge or of tmax: such rays may differ.
    if (a.has_value() != b.has_value() || (a && a->shape != b->shape)) {
      ++differ;
      continue;
    }
    EXPECT_EQ(closed.occluded(p, d, 0.0, tmax), a.has_value());
    if (!a) continue;
    ++hits[static_cast<std::size_t>(a->shape)];
    ASSERT_NEAR(a->t, b->t, 1e-5) << "p " << p.transpose() << " d " << d.transpose();
    ASSERT_GT(a->n.dot(b->n), 1.0 - 1e-9) << "shape " << a->shape;
    ASSERT_LT((a->p - b->p).norm(), 1e-5);
  }
  for (std::size_t i = 0; i < hits.size(); ++i) EXPECT_GT(hits[i], 1000) << "shape " << i;  // each one tested
  EXPECT_LE(differ, kRays / 10000) << differ << " rays of " << kRays << " disagree";
}

// docs/render.md §1, "Where Embree's floats are": a ray may start beyond the cube all shapes lie in (a collision
// deep in an unbounded medium); it is started where it enters the cube all shapes lie in, and
// meets them at the same distance.
TEST(Reach, RaysFromBeyondTheReachMeetWhatTheyPointAt) {
  SceneDesc two_boxes;
  two_boxes.shapes = {box({-0.5, 0, -0.5}, {0.5, 1, 0.5}), box({1, 0, 0}, {2, 1, 1})};
  for (const SceneDesc& scene : {two_boxes, with_embree(two_boxes)}) {
    const Geometry g(scene, {}, {});  // the closed form, then Embree's path
    constexpr double kInf = std::numeric_limits<double>::infinity();
    for (const double far : {2e5, 1e9, 1e20, 1e300}) {
      const Vec3 o(0, 0.5, far);
      const auto hit = g.intersect(o, {0, 0, -1}, 0.0, kInf);
      ASSERT_TRUE(hit.has_value()) << far;
      EXPECT_NEAR(hit->t, far - 0.5, 1e-6 * far) << far;
      EXPECT_EQ(hit->shape, 0);
      EXPECT_TRUE(g.occluded(o, {0, 0, -1}, 0.0, kInf)) << far;
      EXPECT_FALSE(g.occluded(o, {0, 0, -1}, 0.0, 0.5 * far)) << far;         // stops short
      EXPECT_FALSE(g.intersect(o, {0, 0, 1}, 0.0, kInf).has_value()) << far;  // points away
      EXPECT_FALSE(g.occluded(o, {0, 1, 0}, 0.0, kInf)) << far;               // passes beside
    }
  }
}

// The one table, for every kind of shape after its scale and translate (geometry.h, Traced): each
// kind is refused beyond its own reach and traced within it.
TEST(Reach, EveryShapeKindIsRefusedBeyondItsOwnReach) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "weft_reach_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "line.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\n";
  struct Case {
    std::string name;
    double limit;
    std::function<ShapeDesc(double)> at;  // the shape reaching about `reach`
  };
  const std::vector<Case> cases = {
      {"sphere radius", kMaxReachSpheres,
       [](double r) {
         ShapeDesc s;
         s.radius = r;
         return s;
       }},
      {"box", kMaxReachTriangles,
       [](double r) {
         return box({0, 0, 0}, {1, r, 1});
       }},
      {"rectangle", kMaxReachTriangles,
       [](double r) {
         ShapeDesc s;
         s.kind = ShapeKind::rectangle;
         s.corner = {0, 0, 0};
         s.edge_u = {r, 0, 0};
         s.edge_v = {0, 1, 0};
         return s;
       }},
      {"mesh scale", kMaxReachTriangles,
       [&](double r) {
         ShapeDesc s;
         s.kind = ShapeKind::mesh;
         s.file = (dir / "tri.obj").string();
         s.scale = r;
         return s;
       }},
      {"mesh translate", kMaxReachTriangles,
       [&](double r) {
         ShapeDesc s;
         s.kind = ShapeKind::mesh;
         s.file = (dir / "tri.obj").string();
         s.translate = {0, 0, -r};
         return s;
       }},
      {"curves radius", kMaxReachCurves,
       [&](double r) {
         ShapeDesc s;
         s.kind = ShapeKind::curves;
         s.file = (dir / "line.obj").string();
         s.radius = r;
         return s;
       }},
      {"curves scale", kMaxReachCurves,
       [&](double r) {
         ShapeDesc s;
         s.kind = ShapeKind::curves;
         s.file = (dir / "line.obj").string();
         s.radius = 0.01;
         s.scale = r;
         return s;
       }},
  };
  for (const Case& c : cases) {
    SceneDesc scene;
    scene.source = "reach.json";
    scene.shapes = {box({-1, -1, -1}, {1, 1, 1}), c.at(0.5 * c.limit)};
    EXPECT_NO_THROW(Geometry(scene, {}, {})) << c.name << " within its reach";
    scene.shapes[1] = c.at(2.0 * c.limit);
    EXPECT_THAT([&] { const Geometry g(scene, {}, {}); },
                ::testing::ThrowsMessage<Error>(::testing::HasSubstr("reach.json: shapes[1]: coordinates reach")))
        << c.name;
  }
  // Beside curves, every ray origin meets the curves' test: a ground beyond their reach is refused.
  SceneDesc beside;
  beside.source = "reach.json";
  beside.shapes = {cases[5].at(0.01), cases[1].at(2.0 * kMaxReachCurves)};
  EXPECT_THROW(Geometry(beside, {}, {}), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace weft::render
