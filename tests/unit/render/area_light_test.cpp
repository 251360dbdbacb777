// Next-event estimation of an area light, against the same radiance integrated by quadrature:
// single scattering in a null-bounded slab lit from behind by a rectangle (every shadow ray
// crosses the slab's boundary on its way to the light), and a diffuse plane lit from a steep
// angle (every shadow ray starts at a surface point offset along its normal). A shadow ray that
// reached the emitter's own surface counted the light as blocked: both images came out dark
// (docs/render.md §2, "Shadow rays to a light point"). Tolerances: 5 standard errors of the
// rendered estimate plus the quadrature's own error.
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

using test::Estimate;
using test::image_mean;

constexpr double kPi = std::numbers::pi;

// The slab [−2, 2]² × [0, kDepth] (μ, albedo a, isotropic phase) inside a null box, the
// rectangle light [−1, 1]² at z = −kBelow facing +z with radiance 1, a camera looking straight
// down the z axis with a field of view so narrow that every pixel sees the central ray.
constexpr double kDepth = 0.5;
constexpr double kBelow = 0.5;
constexpr double kMu = 2.0;
constexpr double kAlbedo = 0.9;

std::string slab_scene() {
  return fmt::format(R"({{
    "camera": {{"position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 0.01, "width": 2, "height": 2}},
    "integrator": {{"spp": 40000, "max_depth": 1, "seed": 3}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {{"type": "homogeneous", "law": {{"name": "exponential", "mu": {}}}, "albedo": {}, "g": 0}}}},
    "shapes": [{{"type": "box", "min": [-2, -2, 0], "max": [2, 2, {}], "material": "boundary", "interior": "m"}},
               {{"type": "rectangle", "corner": [-1, -1, {}], "edge_u": [2, 0, 0], "edge_v": [0, 2, 0], "emission": 1}}]
  }})",
                     kMu, kAlbedo, kDepth, -kBelow);
}

// Along the central ray: the light seen through the slab, e^{−μ·depth}, plus single scattering,
// ∫ e^{−μs} μ a/(4π) ∫_light cos_l/r² e^{−μ·(chord to the slab's lower face)} dA ds, by the
// midpoint rule (the integrand is smooth: r ≥ kBelow).
double single_scattering_quadrature() {
  constexpr int kS = 200;
  constexpr int kA = 200;
  double sum = 0.0;
  for (int i = 0; i < kS; ++i) {
    const double s = (i + 0.5) / kS * kDepth;  // depth below the slab's top
    const double z = kDepth - s;               // height of the collision over the lower face
    double light = 0.0;
    for (int j = 0; j < kA; ++j)
      for (int k = 0; k < kA; ++k) {
        const double u = -1.0 + 2.0 * (j + 0.5) / kA;
        const double v = -1.0 + 2.0 * (k + 0.5) / kA;
        const double h = z + kBelow;
        const double r = std::sqrt(u * u + v * v + h * h);
        const double chord = z * r / h;  // the slab is wide enough that every chord leaves by its lower face
        light += (h / r) / (r * r) * std::exp(-kMu * chord);
      }
    light *= 4.0 / (kA * kA);  // the light's area over the cells
    sum += std::exp(-kMu * s) * kMu * kAlbedo / (4.0 * kPi) * light;
  }
  return std::exp(-kMu * kDepth) + sum * kDepth / kS;
}

TEST(AreaLight, SingleScatteringThroughANullBoundaryMatchesQuadrature) {
  const double expected = single_scattering_quadrature();
  const SceneDesc scene = parse_scene(slab_scene(), "slab", ".");
  for (const IntegratorChoice choice : {IntegratorChoice::automatic, IntegratorChoice::general}) {
    RenderOptions options;
    options.integrator = choice;
    const Estimate e = image_mean(render(scene, options).image);
    EXPECT_GT(e.stderr_, 0.0);
    EXPECT_NEAR(e.mean, expected, 5.0 * e.stderr_ + 1e-3 * expected)
        << (choice == IntegratorChoice::general ? "general" : "exponential");
  }
}

// A diffuse plane z = 0 (albedo ρ) and the rectangle light [kOff, kOff + 1] × [−0.5, 0.5] at
// height kHeight facing −z: the camera's central ray meets the plane at the origin, which sees
// the light at 60°–80° from its normal. L = ρ/π ∫ cos_i cos_l / r² dA (radiance 1).
constexpr double kRho = 0.5;
constexpr double kHeight = 0.3;
constexpr double kOff = 0.6;

double diffuse_plane_quadrature() {
  constexpr int kA = 400;
  double sum = 0.0;
  for (int j = 0; j < kA; ++j)
    for (int k = 0; k < kA; ++k) {
      const double u = kOff + (j + 0.5) / kA;
      const double v = -0.5 + (k + 0.5) / kA;
      const double r2 = u * u + v * v + kHeight * kHeight;
      sum += kHeight * kHeight / (r2 * r2);  // cos_i = cos_l = h/r
    }
  return kRho / kPi * sum / (kA * kA);
}

TEST(AreaLight, DiffusePlaneLitAtAGrazingAngleMatchesQuadrature) {
  const SceneDesc scene = parse_scene(fmt::format(R"({{
    "camera": {{"position": [0, -1, 3], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 0.01, "width": 2, "height": 2}},
    "integrator": {{"spp": 20000, "max_depth": 1, "seed": 5}},
    "materials": {{"d": {{"type": "diffuse", "albedo": {}}}}},
    "shapes": [{{"type": "rectangle", "corner": [-5, -5, 0], "edge_u": [10, 0, 0], "edge_v": [0, 10, 0], "material": "d"}},
               {{"type": "rectangle", "corner": [{}, -0.5, {}], "edge_u": [0, 1, 0], "edge_v": [1, 0, 0], "emission": 1}}]
  }})",
                                                  kRho, kOff, kHeight),
                                      "plane", ".");
  const double expected = diffuse_plane_quadrature();
  const Estimate e = image_mean(render(scene).image);
  EXPECT_GT(e.stderr_, 0.0);
  EXPECT_NEAR(e.mean, expected, 5.0 * e.stderr_ + 1e-3 * expected);
}

}  // namespace
}  // namespace weft::render
