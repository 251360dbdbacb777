// A scene moved far from the world origin renders the same image statistically (docs/render.md
// §1, "Where Embree's floats are"): Embree's floats and the ray offsets are taken in a frame that
// moves with the scene, so nothing but double rounding depends on where it sits.
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "image_mean.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"

namespace weft::render {
namespace {

/// A slab of scattering medium (mean free path 0.05, 1.08 × 0.42 × 0.44) behind a null box, lit by
/// a directional light, an emitting rectangle and a dim sky, every coordinate moved by `d`. The
/// medium is crossed at its boundaries on most paths, where the ray offsets act: an offset that
/// grew with the distance from the world origin (1e-5 of it, 0.1 at d = 1e4, twice the mean free
/// path) made this image 47 % darker at d = 1e4 and 4 % at d = 1e3.
std::string slab_scene(double d) {
  return fmt::format(
      R"({{"camera": {{"position": [{0}, {1}, {2}], "look_at": [{3}, {4}, {2}], "up": [0, 1, 0], "fov": 35,
                      "width": 40, "height": 30}},
          "integrator": {{"max_depth": 64, "rr_depth": 6, "seed": 1, "spp": 64}},
          "materials": {{"boundary": {{"type": "null"}}}},
          "media": {{"m": {{"type": "homogeneous", "law": {{"name": "exponential", "mu": 20}}, "albedo": 0.9,
                           "g": 0.3}}}},
          "shapes": [{{"type": "box", "min": [{5}, {6}, {7}], "max": [{8}, {9}, {10}], "material": "boundary",
                       "interior": "m"}},
                     {{"type": "rectangle", "corner": [{11}, {12}, {13}], "edge_u": [0, 0, 0.48],
                       "edge_v": [1.248, 0, 0], "emission": 0.5}}],
          "lights": [{{"type": "directional", "direction": [0.5265, -0.766, 0.3687], "irradiance": 3.0}},
                     {{"type": "environment", "radiance": 0.02}}]}})",
      0.12 + d, 0.67 + d, 0.02 + d, 0.5 + d, 0.01 + d, -0.04 + d, -0.2 + d, -0.2 + d, 1.04 + d, 0.22 + d, 0.24 + d,
      -0.124 + d, -0.51 + d, -0.22 + d);
}

TEST(Translation, SlabFarFromTheOriginRendersTheSameMean) {
  const test::Estimate at_origin = test::image_mean(render(parse_scene(slab_scene(0.0), "slab.json", ".")).image);
  // The offsets beyond 1e4 reach the triangles' limit (1e11) only in Embree's frame, which moves
  // with the scene: 1e8 is as traceable as 0 (docs/render.md §1 gives the range, ~1e9 extents).
  for (const double d : {1e2, 1e3, 1e4, 1e6, 1e8}) {
    const test::Estimate moved = test::image_mean(render(parse_scene(slab_scene(d), "slab.json", ".")).image);
    // Two estimates of one mean: 4 standard errors of their difference (the renders share
    // their seed, so the true spread is smaller; before the frame, d = 1e3 was 6 of them off and d = 1e4 73).
    const double tolerance = 4.0 * std::hypot(at_origin.stderr_, moved.stderr_);
    EXPECT_NEAR(moved.mean, at_origin.mean, tolerance) << "scene moved by " << d;
  }
}

/// A 1 mm medium slab (μ = 2, 20 × 1 × 20 mm) over `ground` (a shape of material "k", albedo
/// `albedo`), seen from `camera`, lit by the sun. The ground's size must not change the slab: ray
/// offsets come from the hit shape's own size (docs/render.md §1).
std::string over_ground(const std::string& ground, double albedo,
                        const std::string& camera = R"("position": [0, 40, 0.01], "up": [0, 0, -1], "fov": 20)") {
  return fmt::format(
      R"({{"camera": {{{0}, "look_at": [0, 0, 0], "width": 24, "height": 24}},
          "integrator": {{"spp": 64, "seed": 1}},
          "materials": {{"b": {{"type": "null"}}, "k": {{"type": "diffuse", "albedo": {1}}}}},
          "media": {{"fog": {{"type": "homogeneous", "law": {{"name": "exponential", "mu": 2}}, "albedo": 0.9,
                             "g": 0.0}}}},
          "shapes": [{{"type": "box", "min": [-10, 0, -10], "max": [10, 1, 10], "material": "b", "interior": "fog"}},
                     {2}],
          "lights": [{{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 2}}]}})",
      camera, albedo, ground);
}

/// A ground rectangle of side `side` at height `y`.
std::string rectangle(double side, double y) {
  return fmt::format(
      R"({{"type": "rectangle", "corner": [{0}, {1}, {2}], "edge_u": [{3}, 0, 0], "edge_v": [0, 0, {4}],
          "material": "k"}})",
      -0.5 * side, y, 0.5 * side, side, -side);
}

void expect_same_mean(const std::string& scene, const std::string& reference, const std::string& what) {
  const test::Estimate a = test::image_mean(render(parse_scene(scene, "a.json", ".")).image);
  const test::Estimate b = test::image_mean(render(parse_scene(reference, "b.json", ".")).image);
  EXPECT_NEAR(a.mean, b.mean, 4.0 * std::hypot(a.stderr_, b.stderr_)) << what;
}

// A black floor 1 mm below the slab, the floor's side L: with offsets from the whole scene's size
// (1e-5·L) the mean fell from 0.1933 (L = 100) to 0.1774 (1e4) and 0.00001 (1e5, the slab stepped
// over); from the hit shape's own size it is the same at every L.
TEST(Translation, ALargeGroundLeavesASmallMediumAsItIs) {
  const std::string reference = over_ground(rectangle(100, -1), 0.0);
  for (const double side : {1e4, 1e5, 1e6})
    expect_same_mean(over_ground(rectangle(side, -1), 0.0), reference, fmt::format("floor side {}", side));
}

// Each kind of shape is limited by its own Embree test (geometry.h, Traced): a ground rectangle
// of 4e5 and 1e6 and a ground sphere of radius 1e5 (triangles and spheres, beyond the curves'
// 1e5) render as a ground of 1e4 does (a white ground 30 mm below, beyond its own ray offsets,
// 1e-5 of its size: docs/render.md §1).
TEST(Translation, LargeGroundsAreTraced) {
  const std::string reference = over_ground(rectangle(1e4, -30), 0.8);
  for (const double side : {4e5, 1e6})
    expect_same_mean(over_ground(rectangle(side, -30), 0.8), reference, fmt::format("ground side {}", side));
  expect_same_mean(
      over_ground(R"({"type": "sphere", "center": [0, -100030, 0], "radius": 100000, "material": "k"})", 0.8),
      reference, "ground sphere of radius 1e5");
}

// A camera far away with a narrow field of view (the same view at every distance D) is traced:
// its rays start where they enter the shapes' cube (geometry.cpp embree_ray) and only its distance
// in the smallest shape's extents is limited (kMaxExtentsAway).
TEST(Translation, AFarCameraWithANarrowViewIsTraced) {
  const auto scene = [](double distance) {
    const double fov = 2.0 * std::atan(5.0 / distance) * 180.0 / std::numbers::pi;
    return over_ground(
        rectangle(1e4, -10), 0.8,
        fmt::format(R"("position": [0, {}, {}], "up": [0, 1, 0], "fov": {})", 0.6 * distance, 0.8 * distance, fov));
  };
  for (const double d : {1.5e5, 1e6}) expect_same_mean(scene(d), scene(100), fmt::format("camera at {}", d));
}

}  // namespace
}  // namespace weft::render
