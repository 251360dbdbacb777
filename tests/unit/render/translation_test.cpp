// A scene moved far from the world origin renders the same image statistically (docs/render.md
// §1, "Where Embree's floats are"): Embree's floats and the ray offsets are taken in a frame that
// moves with the scene, so nothing but double rounding depends on where it sits.
#include <cmath>
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

}  // namespace
}  // namespace weft::render
