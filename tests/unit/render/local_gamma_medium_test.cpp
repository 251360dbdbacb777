// The local-gamma scene medium (docs/render.md §5b): `weft fit --block` fields rendered as a
// heterogeneous gamma medium. A constant field is the homogeneous gamma law (two estimators, one
// answer, within 5 standard errors per pixel); a purely absorbing slab shows T_Q(chord) × the
// background; bad fields and parameters are one-line errors at load.
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "image_mean.h"
#include "weft/core/error.h"
#include "weft/render/local_gamma.h"
#include "weft/render/medium.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;

SceneDesc scene_from(const std::string& json) { return parse_scene(json, "test scene", "."); }

/// Fields of n³ coarse voxels of size h from `lo` on every axis, constant mean C and variance V;
/// `skip` leaves out one of the four grids (to test a file without it).
fs::path write_fields(const std::string& name, int n, double h, double lo, float c, float v,
                      const std::string& skip = "") {
  const fs::path path = fs::temp_directory_path() / ("weft_lg_medium_" + name + ".vdb");
  std::vector<volume::Grid> grids;
  for (const std::string grid_name :
       {"mean_concentration", "var_concentration_x", "var_concentration_y", "var_concentration_z"}) {
    if (grid_name == skip) continue;
    volume::Grid g(h, grid_name);
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) g.set_value(i, j, k, grid_name == "mean_concentration" ? c : v);
    g.set_origin({lo, lo, lo});
    grids.push_back(g);
  }
  volume::save_grids(grids, path);
  return path;
}

using test::Estimate;
using test::image_mean;

/// The same cube scene as render_test's grid-medium tests: [-0.5, 0.5]³ of `medium`.
std::string cube_scene(const std::string& medium, int spp) {
  return fmt::format(R"({{
    "camera": {{"position": [0.6, 0.9, 2.6], "look_at": [0, 0, 0], "fov": 40, "width": 10, "height": 10}},
    "integrator": {{"spp": {}, "max_depth": 200, "rr_depth": 5, "seed": 21}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {}}},
    "shapes": [{{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "boundary", "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 0.5}}, {{"type": "point", "position": [1, 2, 1], "intensity": 2}}]
  }})",
                     spp, medium);
}

/// Per-pixel χ² of two independent renders: z-score against its expectation, plus the means.
void expect_same_image(const Image& a, const Image& b) {
  double chi2 = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = static_cast<double>(a.rgb[i]) - b.rgb[i];
    const double v = static_cast<double>(a.variance[i]) + b.variance[i];
    if (v > 0.0) {
      chi2 += d * d / v;
      ++n;
    } else {
      EXPECT_LT(std::abs(d), 1e-5) << "noiseless pixel " << i;
    }
  }
  ASSERT_GT(n, 0);
  EXPECT_LT(std::abs((chi2 - n) / std::sqrt(2.0 * n)), 5.0) << "chi2 " << chi2 << " over " << n << " pixel channels";
  const Estimate ea = image_mean(a);
  const Estimate eb = image_mean(b);
  EXPECT_NEAR(ea.mean, eb.mean, 5.0 * std::hypot(ea.stderr_, eb.stderr_));
}

struct ConstantCase {
  std::string label;
  float mean;
  float var;
};

class ConstantLocalGamma : public ::testing::TestWithParam<ConstantCase> {};

// A constant field C̄, V with σ is the homogeneous gamma law μ̄ = σC̄, α = C̄²/V in reciprocal
// mode: T_Q per voxel is that law, and the per-voxel scatterer partner is its T_S. The field
// (14³ voxels of 0.1 from −0.7) covers the cube whatever the voxel-centring convention.
TEST_P(ConstantLocalGamma, RendersLikeHomogeneousGammaMedium) {
  const ConstantCase& c = GetParam();
  constexpr double kSigma = 6.0;
  const fs::path fields = write_fields(c.label, 14, 0.1, -0.7, c.mean, c.var);
  const SceneDesc local = scene_from(
      cube_scene(fmt::format(R"({{"type": "local-gamma", "fields": "{}", "sigma": {}, "albedo": 0.8, "g": 0.3}})",
                             fields.string(), kSigma),
                 64));
  const double mu = kSigma * c.mean;
  // V = 0 is the exponential limit α → ∞ of the gamma law.
  const std::string law = c.var == 0.0F ? fmt::format(R"({{"name": "exponential", "mu": {}}})", mu)
                                        : fmt::format(R"({{"name": "gamma", "mean_extinction": {}, "alpha": {}}})", mu,
                                                      static_cast<double>(c.mean) * c.mean / c.var);
  const SceneDesc homogeneous =
      scene_from(cube_scene(fmt::format(R"({{"law": {}, "albedo": 0.8, "g": 0.3}})", law), 64));
  const RenderResult a = render(local);
  RenderOptions other_seed;
  other_seed.seed = 4321;
  const RenderResult b = render(homogeneous, other_seed);
  EXPECT_TRUE(a.stats.features.heterogeneous);
  EXPECT_TRUE(a.stats.features.general_media);
  EXPECT_FALSE(a.stats.features.non_reciprocal);
  EXPECT_EQ(a.stats.integrator, "volpath<general>");
  EXPECT_EQ(a.stats.invalid_samples, 0U);
  expect_same_image(a.image, b.image);
}

INSTANTIATE_TEST_SUITE_P(Fields, ConstantLocalGamma,
                         ::testing::Values(ConstantCase{"alpha2", 0.5F, 0.125F}, ConstantCase{"alpha0_5", 0.5F, 0.5F},
                                           ConstantCase{"exponential", 0.5F, 0.0F}),
                         [](const auto& info) { return info.param.label; });

// A purely absorbing slab |z| < 0.25 of a constant field in front of a uniform background of
// radiance 1: each pixel is the pixel-average of T_Q(chord) = (1 + σt/β)^{−α}.
TEST(LocalGammaMedium, AbsorbingSlabShowsSourceTransmittanceOfChord) {
  constexpr double kThickness = 0.5;
  constexpr double kSigma = 4.0;
  constexpr float kMean = 0.5F;
  constexpr float kVar = 0.5F;  // α = 0.5: far from exponential
  // 50 × 50 × 8 voxels of 0.1 from (−2.5, −2.5, −0.4): covers the slab's visible part.
  const fs::path path = fs::temp_directory_path() / "weft_lg_medium_slab.vdb";
  {
    std::vector<volume::Grid> grids;
    for (const std::string name :
         {"mean_concentration", "var_concentration_x", "var_concentration_y", "var_concentration_z"}) {
      volume::Grid g(0.1, name);
      for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 50; ++j)
          for (int i = 0; i < 50; ++i) g.set_value(i, j, k, name == "mean_concentration" ? kMean : kVar);
      g.set_origin({-2.5, -2.5, -0.4});
      grids.push_back(g);
    }
    volume::save_grids(grids, path);
  }
  const std::string json = fmt::format(R"({{
    "camera": {{"position": [0, 0, 3], "look_at": [0, 0, 0], "fov": 40, "width": 6, "height": 6}},
    "integrator": {{"spp": 256, "seed": 11}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {{"type": "local-gamma", "fields": "{}", "sigma": {}, "albedo": 0}}}},
    "shapes": [{{"type": "box", "min": [-2, -2, {}], "max": [2, 2, {}], "material": "boundary", "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                                       path.string(), kSigma, -kThickness / 2, kThickness / 2);
  const SceneDesc scene = scene_from(json);
  const RenderResult r = render(scene);
  const double alpha = static_cast<double>(kMean) * kMean / kVar;
  const double beta = static_cast<double>(kMean) / kVar;
  const CameraDesc& cam = scene.camera;
  const double tan_half = std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0);
  constexpr int kSub = 32;
  double max_z = 0.0;
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      double expected = 0.0;
      for (int j = 0; j < kSub; ++j)
        for (int i = 0; i < kSub; ++i) {
          const double sx = (2.0 * (x + (i + 0.5) / kSub) / cam.width - 1.0) * tan_half;
          const double sy = (1.0 - 2.0 * (y + (j + 0.5) / kSub) / cam.height) * tan_half;
          const double chord = kThickness * std::sqrt(1.0 + sx * sx + sy * sy);
          expected += std::pow(1.0 + kSigma * chord / beta, -alpha);
        }
      expected /= kSub * kSub;
      const double sigma = std::sqrt(r.image.var_at(x, y, 0));
      EXPECT_NEAR(r.image.at(x, y, 0), expected, 5.0 * sigma + 1e-4) << "pixel " << x << "," << y;
      max_z = std::max(max_z, std::abs(r.image.at(x, y, 0) - expected) / (sigma + 1e-12));
    }
  }
  RecordProperty("max_abs_z", std::to_string(max_z));
}

// The scatterer side of a constant field is the gamma partner T_S = (1 + σt/β)^{−(α+1)}.
TEST(LocalGammaMedium, ScattererSegmentsUseThePerVoxelReciprocalPartner) {
  const double c = 2.0, v = 0.5, sigma = 1.5;
  LocalGammaField f(write_fields("partner", 8, 1.0, -0.5, static_cast<float>(c), static_cast<float>(v)), sigma);
  const double alpha = c * c / v, beta = c / v;
  const volume::Ray ray{{3.0, 3.0, -0.5}, {0.0, 0.0, 1.0}};
  for (const double t : {0.1, 1.0, 2.5, 6.0}) {
    const double expected = -(alpha + 1.0) * std::log1p(sigma * t / beta);
    EXPECT_NEAR(f.log_transmittance(ray, 0.0, t, transmittance::Origin::scatterer), expected,
                1e-9 * (1.0 + std::abs(expected)))
        << t;
  }
  // Sampling the scatterer side inverts the same H: H(t*) = h.
  const auto clone = f.clone();
  for (const double h : {0.05, 0.7, 2.0}) {
    const double t = clone->sample_distance(ray, 0.0, 7.0, h, transmittance::Origin::scatterer);
    EXPECT_NEAR(-f.log_transmittance(ray, 0.0, t, transmittance::Origin::scatterer), h, 1e-9) << h;
  }
}

TEST(LocalGammaMedium, RoundTripsThroughJson) {
  const fs::path fields = write_fields("roundtrip", 4, 0.5, -1.0, 0.3F, 0.02F);
  const SceneDesc a = scene_from(fmt::format(
      R"({{"media": {{"m": {{"type": "local-gamma", "fields": "{}", "sigma": 7.5, "albedo": [0.9, 0.8, 0.7], "g": -0.2}}}}}})",
      fields.string()));
  const std::string once = scene_to_json(a);
  const SceneDesc b = scene_from(once);
  EXPECT_EQ(scene_to_json(b), once);
  const MediumDesc& m = b.media.at("m");
  EXPECT_EQ(m.kind, MediumKind::local_gamma);
  EXPECT_EQ(m.file, fields.string());
  EXPECT_EQ(m.sigma, 7.5);
  EXPECT_EQ(m.g, -0.2);
  EXPECT_EQ(m.albedo[2], 0.7);
}

/// The error message of parsing `media` (a JSON object of media), or "" when it parses.
std::string error_of(const std::string& medium) {
  try {
    // The fields file is read when the medium is built (render/world), still before any render.
    (void)build_medium(scene_from(R"({"media": {"m": )" + medium + "}}"), "m");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void expect_one_line_naming(const std::string& msg, const std::vector<std::string>& parts) {
  ASSERT_FALSE(msg.empty()) << "no error";
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
}

TEST(LocalGammaMedium, BadInputIsAOneLineError) {
  const std::string ok = write_fields("ok", 2, 1.0, 0.0, 0.5F, 0.1F).string();
  const auto medium = [](const std::string& fields, const std::string& extra) {
    return fmt::format(R"({{"type": "local-gamma", "fields": "{}"{}}})", fields, extra);
  };
  EXPECT_EQ(error_of(medium(ok, R"(, "sigma": 3)")), "");
  expect_one_line_naming(error_of(medium("/nonexistent/fit.vdb", "")), {"media.m", "/nonexistent/fit.vdb"});
  expect_one_line_naming(error_of(R"({"type": "local-gamma"})"), {"media.m", "fields"});
  expect_one_line_naming(error_of(medium(ok, R"(, "sigma": -1)")), {"media.m", "sigma"});
  expect_one_line_naming(error_of(medium(ok, R"(, "sigma": 0)")), {"media.m", "sigma"});
  expect_one_line_naming(error_of(medium(ok, R"(, "albedo": -0.5)")), {"media.m", "albedo"});
  // Misspelt or inapplicable keys are named, with the closest known key.
  expect_one_line_naming(error_of(medium(ok, R"(, "sigm": 3)")), {"unknown key 'sigm'", "sigma"});
  expect_one_line_naming(error_of(medium(ok, R"(, "law": "gamma")")), {"unknown key 'law'"});
  expect_one_line_naming(error_of(R"({"type": "local-gama", "fields": "x"})"), {"local-gamma"});
  // A file without one of the variance grids.
  const std::string no_var = write_fields("novar", 2, 1.0, 0.0, 0.5F, 0.1F, "var_concentration_y").string();
  expect_one_line_naming(error_of(medium(no_var, "")), {"media.m", "var_concentration_y"});
  // Negative and NaN values in the grids.
  const std::string negative = write_fields("negative", 2, 1.0, 0.0, -0.5F, 0.1F).string();
  expect_one_line_naming(error_of(medium(negative, "")), {"media.m", "mean_concentration", ">= 0"});
  const std::string nan_var =
      write_fields("nanvar", 2, 1.0, 0.0, 0.5F, std::numeric_limits<float>::quiet_NaN()).string();
  expect_one_line_naming(error_of(medium(nan_var, "")), {"media.m", "var_concentration_x", "nan"});
  // An empty mean grid.
  const std::string empty = write_fields("empty", 0, 1.0, 0.0, 0.5F, 0.1F).string();
  expect_one_line_naming(error_of(medium(empty, "")), {"media.m", "empty"});
}

}  // namespace
}  // namespace weft::render
