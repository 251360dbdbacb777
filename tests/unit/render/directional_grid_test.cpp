// The direction-dependent grid medium (render::DeltaTrackingGridMedium on three per-axis grids,
// docs/render.md §6d):
// extinction σ(ω) = Σ_a ω_a² σ_a from three per-axis grids, tracked against one majorant grid
// over the three channels. Closed forms: through a uniform block of length ℓ the transmittance
// along axis a is e^{−σ_a ℓ}, along ω = (e_a + e_b)/√2 it is e^{−(σ_a + σ_b)ℓ/2}; ratio tracking's
// mean and delta tracking's collision probability are compared with them within 5 standard
// errors; a render is the same bytes for 1 and 2 threads. The white furnace and the absorbing
// cube of every medium kind (media_kinds_test.cpp, `grid_directional`) cover it too.
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/render/medium.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/render/world.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;

constexpr double kSigma = 2.0;                           // extinction per unit value
constexpr std::array<double, 3> kValue{0.25, 1.0, 0.5};  // per-axis values: σ_a = 0.5, 2, 1
constexpr double kLength = 1.0;                          // the cube [-0.5, 0.5]³

/// One file with three grids "sx", "sy", "sz" of 10³ voxels over [-0.5, 0.5]³, each uniform.
std::string axis_file() {
  const fs::path path = fs::temp_directory_path() / "weft_directional_grid.vdb";
  std::vector<volume::Grid> grids;
  for (int a = 0; a < 3; ++a) {
    volume::Grid g(0.1, fmt::format("s{}", "xyz"[a]));
    for (int i = 0; i < 10; ++i)
      for (int j = 0; j < 10; ++j)
        for (int k = 0; k < 10; ++k) g.set_value(i, j, k, static_cast<float>(kValue[static_cast<std::size_t>(a)]));
    g.set_origin({-0.5, -0.5, -0.5});
    grids.push_back(g);
  }
  volume::save_grids(grids, path);
  return path.string();
}

std::string medium_json(const std::string& file, const std::string& albedo, const std::string& extra = "") {
  return fmt::format(R"({{"type": "grid", "file": "{}", "axis_grids": ["sx", "sy", "sz"], "sigma": {},
                         "albedo": {}{}}})",
                     file, kSigma, albedo, extra);
}

std::string box_scene(const std::string& medium, int spp, int width) {
  return fmt::format(R"({{
    "camera": {{"position": [0.3, 0.2, 3.2], "look_at": [0, 0, 0], "fov": 30, "width": {w}, "height": {w}}},
    "integrator": {{"spp": {spp}, "max_depth": 100000, "rr_depth": 100000, "seed": 3}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {medium}}},
    "shapes": [{{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "boundary",
                 "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                     fmt::arg("w", width), fmt::arg("spp", spp), fmt::arg("medium", medium));
}

TEST(DirectionalGrid, TransmittanceThroughOneBlockIsTheClosedFormAlongEachAxisAndBetween) {
  const SceneDesc scene = parse_scene(box_scene(medium_json(axis_file(), "0"), 1, 4), "directional", ".");
  const auto medium = build_medium(scene, "m");
  EXPECT_EQ(medium->traits().kind, "grid");
  auto scratch = medium->make_scratch();
  const double s2 = std::sqrt(0.5);
  // Directions and their σ(ω): the three axes, and halfway between two of them.
  const std::vector<std::pair<Vec3, double>> cases = {
      {Vec3(1, 0, 0), kSigma * kValue[0]},
      {Vec3(0, 1, 0), kSigma * kValue[1]},
      {Vec3(0, 0, -1), kSigma * kValue[2]},
      {Vec3(s2, s2, 0), kSigma * (kValue[0] + kValue[1]) / 2},
      {Vec3(0, -2 * s2, 2 * s2), kSigma * (kValue[1] + kValue[2]) / 2},  // not unit: the weights are ω_a²/|ω|²
  };
  const int n = 40000;
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const auto& [d, sigma] = cases[c];
    const Vec3 u = d.normalized();
    const double chord = kLength / std::max({std::abs(u[0]), std::abs(u[1]), std::abs(u[2])}) * 0.999;
    const Vec3 o = -0.5 * chord * u;        // the chord through the centre, inside the cube
    const double t_len = chord * d.norm();  // t along the direction as given
    const double expected = std::exp(-sigma * chord);
    Pcg32 rng = stream_for(11, c);
    double sum = 0.0;
    double sum2 = 0.0;
    int collided = 0;
    for (int i = 0; i < n; ++i) {
      const double tr =
          medium->transmittance(o, d, t_len / d.norm(), transmittance::Origin::source, rng, scratch.get());
      sum += tr;
      sum2 += tr * tr;
      collided +=
          medium->sample_flight(o, d, t_len / d.norm(), transmittance::Origin::source, rng, scratch.get()).collided;
    }
    const double mean = sum / n;
    const double se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, expected, 5 * se + 1e-12) << "ratio tracking, case " << c;
    const double p = 1.0 - expected;
    EXPECT_NEAR(static_cast<double>(collided) / n, p, 5 * std::sqrt(p * (1 - p) / n)) << "delta tracking, case " << c;
  }
}

TEST(DirectionalGrid, SameBytesForOneAndTwoThreads) {
  const SceneDesc scene = parse_scene(box_scene(medium_json(axis_file(), "0.8"), 8, 16), "threads", ".");
  const auto with_threads = [&](unsigned threads) {
    const ThreadLimit limit(threads);
    return render(scene).image;
  };
  const Image a = with_threads(1);
  const Image b = with_threads(2);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.variance, b.variance);
}

TEST(DirectionalGrid, RoundTripsAndBadInputIsAOneLineError) {
  const std::string file = axis_file();
  const SceneDesc a = parse_scene(box_scene(medium_json(file, "0.5"), 1, 4), "round trip", ".");
  const SceneDesc b = parse_scene(scene_to_json(a), "round trip", ".");
  EXPECT_EQ(b.media.at("m").axis_grids, (std::vector<std::string>{"sx", "sy", "sz"}));
  const auto refused = [&](const std::string& medium, const std::string& what) {
    EXPECT_THAT([&] { (void)build_medium(parse_scene(box_scene(medium, 1, 4), "bad", "."), "m"); },
                weft::test::throws_one_line_error_with({what}))
        << medium;
  };
  refused(fmt::format(R"({{"type": "grid", "file": "{}", "axis_grids": ["sx", "sy"]}})", file),
          "array of 3 grid names");
  refused(fmt::format(R"({{"type": "grid", "file": "{}", "axis_grids": ["sx", "sy", "nope"]}})", file), "nope");
  refused(fmt::format(R"({{"type": "grid", "file": "{}", "grid": "sx", "axis_grids": ["sx", "sy", "sz"]}})", file),
          "not both");
  refused(medium_json(file, "0.5", R"(, "tracking": "optical-depth")"), "needs delta tracking");
  refused(medium_json(file, "0.5", R"(, "law": {"name": "gamma", "mean_extinction": 1, "alpha": 2})"),
          "needs an exponential law");
}

}  // namespace
}  // namespace weft::render
