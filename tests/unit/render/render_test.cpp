// The path tracer against answers known in closed form (white furnaces, absorbing slabs, a point
// light over a plane), two estimators of one answer, and reproducibility. Tolerances are 5
// standard errors of the rendered estimate (per-pixel sample variances), plus float rounding.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "error_matchers.h"
#include "file_size_limit.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/render/environment.h"
#include "weft/render/medium.h"
#include "weft/render/mesh.h"
#include "weft/render/phase.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/render/scene_checks.h"
#include "weft/render/tiling.h"
#include "weft/volume/grid.h"

namespace weft::render {
namespace {

/// What a render of `scene` specialises on: the features of its built world.
Features features_of_scene(const SceneDesc& scene) { return build_world(scene).features; }

constexpr double kFloat = 1e-5;  // images are stored as float

SceneDesc scene_from(const std::string& json) { return parse_scene(json, "test scene", "."); }

/// Mean of channel 0 over pixels [x0,x1)×[y0,y1) and its standard error.
struct Estimate {
  double mean = 0.0;
  double stderr_ = 0.0;
};
Estimate region_mean(const Image& im, int x0, int y0, int x1, int y1) {
  double sum = 0.0;
  double var = 0.0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      sum += im.at(x, y, 0);
      var += im.var_at(x, y, 0);
      ++n;
    }
  return {sum / n, std::sqrt(var) / n};
}

std::string furnace_scene(const std::string& law, const std::string& mode, const std::string& given, int spp) {
  return fmt::format(R"({{
    "camera": {{"position": [0, 0, 3.2], "look_at": [0, 0, 0], "fov": 30, "width": 12, "height": 12}},
    "integrator": {{"spp": {}, "max_depth": 100000, "rr_depth": 100000, "seed": 3}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {{"law": {}, "mode": "{}", "given": "{}", "albedo": 1, "g": 0.3}}}},
    "shapes": [{{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "boundary", "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                     spp, law, mode, given);
}

struct FurnaceCase {
  std::string label;
  std::string law;
  std::string given;
};

class ReciprocalFurnace : public ::testing::TestWithParam<FurnaceCase> {};

// A closed index-matched sphere of a conservative medium under a uniform environment of radiance
// 1 must render 1 everywhere: in reciprocal mode every full path has weight 1 (docs/render.md §2).
TEST_P(ReciprocalFurnace, RendersOneEverywhere) {
  const FurnaceCase& c = GetParam();
  const RenderResult r = render(scene_from(furnace_scene(c.law, "reciprocal", c.given, 96)));
  // The sphere covers the central 6x6 pixels fully.
  const Estimate e = region_mean(r.image, 3, 3, 9, 9);
  EXPECT_NEAR(e.mean, 1.0, 5.0 * e.stderr_ + kFloat) << c.label << " stderr " << e.stderr_;
  EXPECT_GT(e.stderr_, 0.0) << "the medium must have been sampled (NEE and MIS mix)";
  EXPECT_TRUE(r.stats.features.media);
  EXPECT_EQ(r.stats.invalid_samples, 0U);
}

INSTANTIATE_TEST_SUITE_P(
    Laws, ReciprocalFurnace,
    ::testing::Values(FurnaceCase{"exponential", R"({"name": "exponential", "mu": 3})", "source"},
                      FurnaceCase{"linear", R"({"name": "linear", "mean_extinction": 3})", "source"},
                      FurnaceCase{"gamma_a0_5", R"({"name": "gamma", "mean_extinction": 3, "alpha": 0.5})", "source"},
                      FurnaceCase{"gamma_a2", R"({"name": "gamma", "mean_extinction": 3, "alpha": 2})", "source"},
                      FurnaceCase{"gamma_a20", R"({"name": "gamma", "mean_extinction": 3, "alpha": 20})", "source"},
                      FurnaceCase{"gamma_path_k2", R"({"name": "gamma-path", "k": 2, "theta": 0.2})", "scatterer"},
                      FurnaceCase{"gamma_path_k0_5", R"({"name": "gamma-path", "k": 0.5, "theta": 0.5})", "scatterer"}),
    [](const auto& info) { return info.param.label; });

// The narrowest phase lobes a medium takes (|g| = 1 − 1e-6, render/phase.h) keep the furnace at 1:
// near-forward (and near-backward) scattering drawn and weighed without rounding (a furnace at
// g = 1 − 1e-8, refused now, rendered 0.91).
TEST(PhaseLobeFurnace, TheNarrowestPhaseLobesRenderOne) {
  for (const double g : {kMaxAbsG, -kMaxAbsG, 0.99}) {
    std::string scene =
        furnace_scene(R"({"name": "gamma", "mean_extinction": 3, "alpha": 0.5})", "reciprocal", "source", 96);
    const std::string from = R"("g": 0.3)";
    scene.replace(scene.find(from), from.size(), fmt::format(R"("g": {:.17g})", g));
    const RenderResult r = render(scene_from(scene));
    const Estimate e = region_mean(r.image, 3, 3, 9, 9);
    EXPECT_NEAR(e.mean, 1.0, 5.0 * e.stderr_ + kFloat) << "g = " << g << ", stderr " << e.stderr_;
    EXPECT_EQ(r.stats.invalid_samples, 0U) << g;
  }
}

// In `same` mode (T_S = T_Q) transport is not reciprocal: the weight of a path that enters the
// sphere at flight length t_in and leaves after t_out is Σ(t_out)/Σ(t_in) (docs/render.md §3),
// so for a gamma law with α = 0.5 the furnace is not 1. For the exponential law Σ is constant
// and `same` is the reciprocal pair, so it stays 1.
TEST(SameModeFurnace, NonExponentialLawIsNotOne) {
  const RenderResult r = render(
      scene_from(furnace_scene(R"({"name": "gamma", "mean_extinction": 3, "alpha": 0.5})", "same", "source", 1024)));
  const Estimate e = region_mean(r.image, 3, 3, 9, 9);
  EXPECT_GT(std::abs(e.mean - 1.0), 5.0 * e.stderr_) << "mean " << e.mean << " stderr " << e.stderr_;
  RecordProperty("furnace_mean", std::to_string(e.mean) + " +- " + std::to_string(e.stderr_));
  EXPECT_TRUE(r.stats.features.non_reciprocal);
}

TEST(SameModeFurnace, ExponentialLawIsOne) {
  const RenderResult r = render(scene_from(furnace_scene(R"({"name": "exponential", "mu": 3})", "same", "source", 96)));
  const Estimate e = region_mean(r.image, 3, 3, 9, 9);
  EXPECT_NEAR(e.mean, 1.0, 5.0 * e.stderr_ + kFloat);
  EXPECT_FALSE(r.stats.features.non_reciprocal);
}

struct SlabCase {
  std::string label;
  std::string law;
  std::string given;
};

class AbsorbingSlab : public ::testing::TestWithParam<SlabCase> {};

// A purely absorbing slab in front of a uniform background: each pixel is the pixel-average of
// T_Q(chord) (the flight starts at the slab's face, a boundary: source-kind).
TEST_P(AbsorbingSlab, PixelIsSourceTransmittanceOfChord) {
  const SlabCase& c = GetParam();
  constexpr double kThickness = 0.5;
  const std::string json = fmt::format(R"({{
    "camera": {{"position": [0, 0, 3], "look_at": [0, 0, 0], "fov": 40, "width": 6, "height": 6}},
    "integrator": {{"spp": 256, "seed": 11}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {{"law": {}, "given": "{}", "albedo": 0}}}},
    "shapes": [{{"type": "box", "min": [-20, -20, {}], "max": [20, 20, {}], "material": "boundary", "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                                       c.law, c.given, -kThickness / 2, kThickness / 2);
  const SceneDesc scene = scene_from(json);
  const transmittance::TransmittancePair pair = make_medium_pair(scene.media.at("m"), "m");
  const RenderResult r = render(scene);
  const CameraDesc& cam = scene.camera;
  const double tan_half = std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0);
  constexpr int kSub = 32;  // pixel-area average of T_Q(chord) by the midpoint rule
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      double expected = 0.0;
      for (int j = 0; j < kSub; ++j)
        for (int i = 0; i < kSub; ++i) {
          const double sx = (2.0 * (x + (i + 0.5) / kSub) / cam.width - 1.0) * tan_half;
          const double sy = (1.0 - 2.0 * (y + (j + 0.5) / kSub) / cam.height) * tan_half;
          const double cos_z = 1.0 / std::sqrt(1.0 + sx * sx + sy * sy);
          expected += pair.transmittance(transmittance::Origin::source, kThickness / cos_z);
        }
      expected /= kSub * kSub;
      const double sigma = std::sqrt(r.image.var_at(x, y, 0));
      EXPECT_NEAR(r.image.at(x, y, 0), expected, 5.0 * sigma + 1e-4) << c.label << " pixel " << x << "," << y;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Laws, AbsorbingSlab,
    ::testing::Values(SlabCase{"exponential", R"({"name": "exponential", "mu": 2})", "source"},
                      SlabCase{"linear", R"({"name": "linear", "mean_extinction": 1.2})", "source"},
                      SlabCase{"gamma_a0_5", R"({"name": "gamma", "mean_extinction": 2, "alpha": 0.5})", "source"},
                      SlabCase{"gamma_a20", R"({"name": "gamma", "mean_extinction": 2, "alpha": 20})", "source"},
                      SlabCase{"gamma_path_k2", R"({"name": "gamma-path", "k": 2, "theta": 0.3})", "scatterer"}),
    [](const auto& info) { return info.param.label; });

std::string scattering_scene(const std::string& law, int spp) {
  return fmt::format(R"({{
    "camera": {{"position": [0, 1.5, 4], "look_at": [0, 0.5, 0], "fov": 35, "width": 14, "height": 14}},
    "integrator": {{"spp": {}, "max_depth": 200, "rr_depth": 5, "seed": 5}},
    "materials": {{"boundary": {{"type": "null"}}, "floor": {{"type": "diffuse", "albedo": 0.6}}}},
    "media": {{"m": {{"law": {}, "albedo": [0.9, 0.7, 0.5], "g": 0.4}}}},
    "shapes": [
      {{"type": "sphere", "center": [0, 0.8, 0], "radius": 0.8, "material": "boundary", "interior": "m"}},
      {{"type": "rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6], "material": "floor"}},
      {{"type": "rectangle", "corner": [-0.5, 3, -0.5], "edge_u": [0, 0, 1], "edge_v": [1, 0, 0], "emission": 8}}
    ],
    "lights": [{{"type": "environment", "radiance": 0.3}}, {{"type": "point", "position": [2, 2, 2], "intensity": 3}}]
  }})",
                     spp, law);
}

/// z-score of Σ (a−b)²/(var_a+var_b) against its χ² expectation, over pixels with noise.
double chi_square_z(const Image& a, const Image& b, double& max_noiseless_difference) {
  double chi2 = 0.0;
  int n = 0;
  max_noiseless_difference = 0.0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = static_cast<double>(a.rgb[i]) - b.rgb[i];
    const double v = static_cast<double>(a.variance[i]) + b.variance[i];
    if (v > 0.0) {
      chi2 += d * d / v;
      ++n;
    } else {
      max_noiseless_difference = std::max(max_noiseless_difference, std::abs(d));
    }
  }
  return (chi2 - n) / std::sqrt(2.0 * n);
}

// The exponential law runs the fast path (inverse-CDF flights, no pair); the gamma path-length
// law with k = 1, θ = 1/μ is the same law run through the general T_Q/T_S machinery with its own
// sampler. Two estimators, one answer.
TEST(TwoEstimators, ExponentialFastPathEqualsGeneralPath) {
  const RenderResult fast = render(scene_from(scattering_scene(R"({"name": "exponential", "mu": 2.5})", 128)));
  RenderOptions independent;  // a different seed: equal streams would correlate the two images
  independent.seed = 1234;
  const RenderResult general =
      render(scene_from(scattering_scene(R"({"name": "gamma-path", "k": 1, "theta": 0.4})", 128)), independent);
  EXPECT_EQ(fast.stats.integrator, "volpath<exponential>");
  EXPECT_EQ(general.stats.integrator, "volpath<general>");
  double noiseless = 0.0;
  const double z = chi_square_z(fast.image, general.image, noiseless);
  EXPECT_LT(std::abs(z), 5.0);
  EXPECT_LT(noiseless, kFloat);
  const Estimate a = region_mean(fast.image, 0, 0, 14, 14);
  const Estimate b = region_mean(general.image, 0, 0, 14, 14);
  EXPECT_NEAR(a.mean, b.mean, 5.0 * std::hypot(a.stderr_, b.stderr_));
}

TEST(Reproducibility, SameImageForAnyThreadCount) {
  const SceneDesc scene = scene_from(scattering_scene(R"({"name": "gamma", "mean_extinction": 2, "alpha": 0.7})", 8));
  Image one;
  Image two;
  {
    const ThreadLimit limit(1);
    one = render(scene).image;
  }
  {
    const ThreadLimit limit(2);
    two = render(scene).image;
  }
  EXPECT_EQ(one.rgb, two.rgb);
  EXPECT_EQ(one.variance, two.variance);
}

TEST(Reproducibility, SamplePassesDoNotChangeTheImage) {
  const SceneDesc scene = scene_from(scattering_scene(R"({"name": "exponential", "mu": 2})", 6));
  const Image whole = render(scene).image;
  RenderOptions passes;
  int calls = 0;
  passes.on_pass = [&](int, double, const Image&) { ++calls; };
  passes.spp_per_pass = 2;
  const Image split = render(scene, passes).image;
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(whole.rgb, split.rgb);
}

// A render of many samples per pixel runs in passes whose units hold at most
// Tiling::kMaxUnitSamples samples each (a unit is where progress is reported and Ctrl-C stops),
// and the image is the one that passes of any other size give.
TEST(Reproducibility, AHighSppRenderRunsInShortUnitsWithTheSameImage) {
  constexpr int kSpp = 40000;
  const SceneDesc scene = scene_from(fmt::format(R"({{
    "camera": {{"position": [0, 0, 3], "look_at": [0, 0, 0], "fov": 20, "width": 2, "height": 2}},
    "integrator": {{"spp": {}, "seed": 3}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {{"law": {{"name": "exponential", "mu": 1.5}}, "albedo": 0.8}}}},
    "shapes": [{{"type": "sphere", "radius": 1, "material": "boundary", "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                                                 kSpp));
  struct Stages : ProgressSink {
    std::uint64_t render_total = 0;
    void begin(std::string_view label, std::uint64_t total) override {
      if (label == "render") render_total = total;
    }
    void advance(std::uint64_t /*done_so_far*/) override {}
    void end() noexcept override {}
  } stages;
  const World world = build_world(scene);
  const RenderResult bounded = render(world, RenderOptions{}, stages);
  // Every unit is one step of the stage: 4 pixels × kSpp samples over steps of at most the bound.
  EXPECT_GE(stages.render_total * static_cast<std::uint64_t>(Tiling::kMaxUnitSamples), std::uint64_t{4} * kSpp);
  EXPECT_EQ(bounded.stats.spp, kSpp);
  RenderOptions other_passes;
  other_passes.on_pass = [](int, double, const Image&) {};
  other_passes.spp_per_pass = 7001;
  const RenderResult split = render(scene, other_passes);
  EXPECT_EQ(bounded.image.rgb, split.image.rgb);
  EXPECT_EQ(bounded.image.variance, split.image.variance);
}

TEST(Tiling, APassKeepsEveryUnitWithinTheBoundAndTakesAllSamplesWhenItCan) {
  for (const auto& [w, h, spp] : {std::tuple{64, 64, 1024},
                                  {256, 256, 64},
                                  {1024, 768, 8},
                                  {2, 2, 40000},
                                  {64, 64, 1000000},
                                  {1, 1, 1},
                                  {3000, 2000, 100000},
                                  {1, 1, 2000000000}}) {
    const int pass = Tiling::bounded_pass_spp(w, h, spp);
    const long side = Tiling::side_for(w, h, pass);
    EXPECT_GE(pass, 1);
    EXPECT_LE(pass, spp);
    EXPECT_TRUE(pass == 1 || side * side * pass <= Tiling::kMaxUnitSamples) << w << "x" << h << " at " << spp;
    const long whole = Tiling::side_for(w, h, spp);
    if (whole * whole * spp <= Tiling::kMaxUnitSamples) {
      EXPECT_EQ(pass, spp) << w << "x" << h << " at " << spp;
    }
  }
}

TEST(Reproducibility, SeedChangesTheNoise) {
  const SceneDesc scene = scene_from(scattering_scene(R"({"name": "exponential", "mu": 2})", 4));
  RenderOptions other;
  other.seed = 99;
  EXPECT_NE(render(scene).image.rgb, render(scene, other).image.rgb);
}

// Surfaces only. A convex diffuse object under a uniform environment reflects ρ·L_env; glass
// and mirrors of albedo 1 under it are invisible (radiance 1).
TEST(SurfaceFurnace, DiffuseSphereReflectsAlbedo) {
  const RenderResult r = render(scene_from(R"({
    "camera": {"position": [0, 0, 3.2], "look_at": [0, 0, 0], "fov": 60, "width": 12, "height": 12},
    "integrator": {"spp": 64, "seed": 2},
    "materials": {"d": {"type": "diffuse", "albedo": 0.4}},
    "shapes": [{"type": "sphere", "radius": 1, "material": "d"}],
    "lights": [{"type": "environment", "radiance": 1}]
  })"));
  EXPECT_EQ(r.stats.integrator, "surfaces");
  const Estimate e = region_mean(r.image, 4, 4, 8, 8);
  EXPECT_NEAR(e.mean, 0.4, 5.0 * e.stderr_ + kFloat);
  EXPECT_GT(e.stderr_, 0.0);
  EXPECT_NEAR(r.image.at(0, 0, 0), 1.0, kFloat);  // the corner sees the environment only
}

TEST(SurfaceFurnace, GlassAndMirrorConserveEnergy) {
  for (const char* material : {R"({"type": "dielectric", "ior": 1.5, "albedo": 1})", R"({"type": "mirror"})"}) {
    const RenderResult r = render(scene_from(fmt::format(R"({{
      "camera": {{"position": [0, 0, 3.2], "look_at": [0, 0, 0], "fov": 30, "width": 8, "height": 8}},
      "integrator": {{"spp": 16, "max_depth": 1000, "rr_depth": 1000}},
      "materials": {{"m": {}}},
      "shapes": [{{"type": "sphere", "radius": 1, "material": "m"}}],
      "lights": [{{"type": "environment", "radiance": 1}}]
    }})",
                                                         material)));
    const Estimate e = region_mean(r.image, 0, 0, 8, 8);
    EXPECT_NEAR(e.mean, 1.0, 5.0 * e.stderr_ + kFloat) << material;
  }
}

// A point light of intensity I at height h over a diffuse plane: L = ρ/π · I·h/r³.
TEST(PointLight, DiffusePlaneRadianceMatchesClosedForm) {
  constexpr double kRho = 0.5;
  constexpr double kIntensity = 2.0;
  constexpr double kHeight = 1.0;
  const SceneDesc scene = scene_from(R"({
    "camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 50, "width": 5, "height": 5},
    "integrator": {"spp": 64, "max_depth": 1},
    "materials": {"d": {"type": "diffuse", "albedo": 0.5}},
    "shapes": [{"type": "rectangle", "corner": [-10, -10, 0], "edge_u": [20, 0, 0], "edge_v": [0, 20, 0], "material": "d"}],
    "lights": [{"type": "point", "position": [0, 0, 1], "intensity": 2}]
  })");
  const RenderResult r = render(scene);
  const double tan_half = std::tan(0.5 * 50.0 * std::numbers::pi / 180.0);
  constexpr int kSub = 64;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) {
      double expected = 0.0;
      for (int j = 0; j < kSub; ++j)
        for (int i = 0; i < kSub; ++i) {
          // Pinhole at z = 3 looking down -z; the pixel ray meets z = 0 at 3·(sx, sy).
          const double sx = (2.0 * (x + (i + 0.5) / kSub) / 5.0 - 1.0) * tan_half;
          const double sy = (1.0 - 2.0 * (y + (j + 0.5) / kSub) / 5.0) * tan_half;
          const double px = 3.0 * sx;
          const double py = 3.0 * sy;
          const double r2 = px * px + py * py + kHeight * kHeight;
          expected += kRho / std::numbers::pi * kIntensity * kHeight / (r2 * std::sqrt(r2));
        }
      expected /= kSub * kSub;
      EXPECT_NEAR(r.image.at(x, y, 0), expected, 5.0 * std::sqrt(r.image.var_at(x, y, 0)) + 1e-4 * expected)
          << x << "," << y;
    }
}

TEST(Features, SelectTheSpecialisedIntegrator) {
  const Features none =
      features_of_scene(scene_from(R"({"materials": {"d": {}}, "shapes": [{"type": "sphere", "material": "d"}]})"));
  EXPECT_FALSE(none.media);
  const Features exp = features_of_scene(scene_from(scattering_scene(R"({"name": "exponential", "mu": 1})", 1)));
  EXPECT_TRUE(exp.media);
  EXPECT_FALSE(exp.general_media);
  const Features gam =
      features_of_scene(scene_from(scattering_scene(R"({"name": "gamma", "mean_extinction": 1, "alpha": 2})", 1)));
  EXPECT_TRUE(gam.general_media);
  EXPECT_FALSE(gam.non_reciprocal);
}

// The surface-only specialisation computes what the general integrator computes, without the
// medium bookkeeping (same random numbers, so equal up to Embree's occlusion vs closest-hit).
TEST(Features, SurfaceSpecialisationMatchesGeneralIntegrator) {
  const SceneDesc scene = scene_from(R"({
    "camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov": 40, "width": 10, "height": 10},
    "integrator": {"spp": 4},
    "materials": {"d": {"type": "diffuse", "albedo": 0.5}, "g": {"type": "dielectric"}},
    "shapes": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "g"},
               {"type": "rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6], "material": "d"}],
    "lights": [{"type": "point", "position": [1, 2, 1], "intensity": 2}, {"type": "environment", "radiance": 0.2}]
  })");
  const RenderResult special = render(scene);
  RenderOptions general;
  general.integrator = IntegratorChoice::general;
  const RenderResult full = render(scene, general);
  EXPECT_EQ(special.stats.integrator, "surfaces");
  EXPECT_EQ(full.stats.integrator, "volpath<general>");
  for (std::size_t i = 0; i < special.image.rgb.size(); ++i)
    EXPECT_NEAR(special.image.rgb[i], full.image.rgb[i], 1e-5 * (1.0 + full.image.rgb[i]));
  const SceneDesc with_medium =
      scene_from(furnace_scene(R"({"name": "gamma", "mean_extinction": 1, "alpha": 2})", "reciprocal", "source", 1));
  RenderOptions too_special;
  too_special.integrator = IntegratorChoice::exponential;
  EXPECT_THROW((void)render(with_medium, too_special), Error);
}

/// A 10³ grid of constant concentration 0.5 filling [-0.5, 0.5]³, saved as .vdb.
/// n³ voxels of `value` filling the cube [-0.5, 0.5]³, saved as `name`.vdb.
std::string cube_grid_file(const std::string& name, int n, float value) {
  const auto path = std::filesystem::temp_directory_path() / (name + ".vdb");
  volume::Grid grid(1.0 / n, "density");
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) grid.set_value(i, j, k, value);
  grid.set_origin({-0.5, -0.5, -0.5});
  grid.save(path);
  return path.string();
}

std::string constant_grid_file() { return cube_grid_file("weft_render_constant_grid", 10, 0.5f); }

/// A cube [-0.5, 0.5]³ of `medium` (JSON), lit by the environment and a point light.
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

void expect_same_image(const Image& a, const Image& b) {
  double noiseless = 0.0;
  const double z = chi_square_z(a, b, noiseless);
  EXPECT_LT(std::abs(z), 5.0);
  EXPECT_LT(noiseless, kFloat);
  const Estimate ea = region_mean(a, 0, 0, a.width, a.height);
  const Estimate eb = region_mean(b, 0, 0, b.width, b.height);
  EXPECT_NEAR(ea.mean, eb.mean, 5.0 * std::hypot(ea.stderr_, eb.stderr_));
}

// A grid of constant concentration C with σ is the homogeneous medium μ = σC: delta tracking
// through the grid (majorant, DDA-free point lookups, ratio-tracked shadows) gives the image of
// the homogeneous fast path.
TEST(GridMedium, ConstantGridEqualsHomogeneousMedium) {
  const std::string file = constant_grid_file();
  const RenderResult grid = render(scene_from(
      cube_scene(fmt::format(R"({{"type": "grid", "file": "{}", "sigma": 6, "albedo": 0.8, "g": 0.3}})", file), 64)));
  RenderOptions other_seed;
  other_seed.seed = 4242;
  const RenderResult homogeneous = render(
      scene_from(cube_scene(R"({"law": {"name": "exponential", "mu": 3}, "albedo": 0.8, "g": 0.3})", 64)), other_seed);
  EXPECT_TRUE(grid.stats.features.heterogeneous);
  expect_same_image(grid.image, homogeneous.image);
}

// Two estimators, one answer: delta + ratio tracking vs sampling the optical depth and marching
// the DDA to it (exact τ for shadows).
TEST(GridMedium, DeltaTrackingEqualsOpticalDepthSampling) {
  const std::string file = constant_grid_file();
  const std::string medium = R"({{"type": "grid", "file": "{}", "sigma": 6, "albedo": 0.8, "tracking": "{}"}})";
  const RenderResult delta = render(scene_from(cube_scene(fmt::format(fmt::runtime(medium), file, "delta"), 64)));
  RenderOptions other_seed;
  other_seed.seed = 77;
  const RenderResult depth =
      render(scene_from(cube_scene(fmt::format(fmt::runtime(medium), file, "optical-depth"), 64)), other_seed);
  expect_same_image(delta.image, depth.image);
}

// Voxels so thick (μh = 3 > 1.5 crossings per voxel length) that the medium walks them exactly
// instead of tracking against majorants: same image as the homogeneous medium; the constant
// grid above (μh = 0.3) keeps tracking.
TEST(GridMedium, OpticallyThickVoxelsAreWalkedExactly) {
  const std::string path = cube_grid_file("weft_render_thick_voxels", 2, 1.0f);
  const auto shared = std::make_shared<const volume::Grid>(volume::Grid::load(path, "density"));
  EXPECT_EQ(DeltaTrackingGridMedium(shared, 6.0, Rgb(0.8, 0.8, 0.8), 0.0).traits().estimator,
            "exact voxel walk (optically thick voxels)");
  const auto thin = std::make_shared<const volume::Grid>(volume::Grid::load(constant_grid_file(), "density"));
  EXPECT_EQ(DeltaTrackingGridMedium(thin, 6.0, Rgb(0.8, 0.8, 0.8), 0.0).traits().estimator, "delta + ratio tracking");
  const RenderResult grid = render(scene_from(
      cube_scene(fmt::format(R"({{"type": "grid", "file": "{}", "sigma": 6, "albedo": 0.8, "g": 0.3}})", path), 64)));
  RenderOptions other_seed;
  other_seed.seed = 99;
  const RenderResult homogeneous = render(
      scene_from(cube_scene(R"({"law": {"name": "exponential", "mu": 6}, "albedo": 0.8, "g": 0.3})", 64)), other_seed);
  expect_same_image(grid.image, homogeneous.image);
}

// Non-exponential by optical depth: a gamma law in τ over a constant grid (τ = σC·t) is the
// homogeneous gamma law with mean extinction σC.
TEST(GridMedium, NonExponentialGridEqualsHomogeneousLaw) {
  const std::string file = constant_grid_file();
  const RenderResult grid = render(scene_from(
      cube_scene(fmt::format(R"({{"type": "grid", "file": "{}", "sigma": 6, "tracking": "optical-depth", "albedo": 0.8,
                       "law": {{"name": "gamma", "mean_extinction": 1, "alpha": 0.5}}}})",
                             file),
                 64)));
  RenderOptions other_seed;
  other_seed.seed = 99;
  const RenderResult homogeneous = render(
      scene_from(cube_scene(R"({"law": {"name": "gamma", "mean_extinction": 3, "alpha": 0.5}, "albedo": 0.8})", 64)),
      other_seed);
  expect_same_image(grid.image, homogeneous.image);
}

TEST(GridMedium, BadGridInputIsReported) {
  EXPECT_THROW((void)scene_from(R"({"media": {"m": {"type": "grid", "file": "/nonexistent/x.vdb"}}})"), Error);
  const std::string file = constant_grid_file();
  // The grid is read when the medium is built (render/world), still before any render.
  EXPECT_THAT(
      [&] {
        (void)build_medium(
            scene_from(fmt::format(
                R"({{"media": {{"m": {{"type": "grid", "file": "{}", "law": {{"name": "gamma", "mean_extinction": 1, "alpha": 2}}}}}}}})",
                file)),
            "m");
      },
      ::testing::ThrowsMessage<Error>(::testing::HasSubstr("optical-depth")))
      << "delta tracking of a gamma law must be refused";
}

// An OBJ mesh with the box's own triangles renders the box's image exactly (same seed): the
// mesh path (reader, scale/translate, winding → inside/outside of the medium) is the box path.
TEST(MeshShape, ObjCubeRendersLikeTheBox) {
  const auto path = std::filesystem::temp_directory_path() / "weft_render_cube.obj";
  {
    const TriangleMesh cube = box_mesh(Vec3(-1, -1, -1), Vec3(1, 1, 1));
    std::ofstream out(path);
    for (const auto& v : cube.vertices) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    for (const auto& t : cube.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  }
  const std::string medium = R"({"law": {"name": "gamma", "mean_extinction": 3, "alpha": 0.5}, "albedo": 0.8})";
  std::string box = cube_scene(medium, 8);
  std::string mesh = box;
  const std::string box_shape = R"("type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5])";
  mesh.replace(mesh.find(box_shape), box_shape.size(),
               fmt::format(R"("type": "mesh", "file": "{}", "scale": 0.5, "translate": [0, 0, 0])", path.string()));
  const Image a = render(scene_from(box)).image;
  const Image b = render(scene_from(mesh)).image;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) EXPECT_NEAR(a.rgb[i], b.rgb[i], kFloat * (1.0 + a.rgb[i]));
  std::filesystem::remove(path);
}

// An area light tests light sampling, BSDF sampling and their MIS weights together: below the
// centre of a w×w emitter of radiance L at height h, a Lambertian plane of albedo ρ has
// radiance ρ·L·F with F the form factor of the rectangle, 4 corners of
// F_c = (1/2π)[A/√(1+A²)·atan(B/√(1+A²)) + B/√(1+B²)·atan(A/√(1+B²))], A = B = (w/2)/h.
TEST(AreaLight, RadianceUnderRectangleMatchesFormFactor) {
  constexpr double kRho = 0.6;
  constexpr double kL = 3.0;
  const RenderResult r = render(scene_from(R"({
    "camera": {"position": [0, 0, 0.5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 1, "width": 4, "height": 4},
    "integrator": {"spp": 512, "max_depth": 1, "seed": 8},
    "materials": {"d": {"type": "diffuse", "albedo": 0.6}},
    "shapes": [
      {"type": "rectangle", "corner": [-20, -20, 0], "edge_u": [40, 0, 0], "edge_v": [0, 40, 0], "material": "d"},
      {"type": "rectangle", "corner": [-1, -1, 1], "edge_u": [0, 2, 0], "edge_v": [2, 0, 0], "emission": 3}
    ]
  })"));
  const double a = 1.0;  // (w/2)/h with w = 2, h = 1
  const double s = std::sqrt(1.0 + a * a);
  const double corner = (a / s * std::atan(a / s) + a / s * std::atan(a / s)) / (2.0 * std::numbers::pi);
  const double expected = kRho * kL * 4.0 * corner;
  const Estimate e = region_mean(r.image, 0, 0, 4, 4);
  EXPECT_NEAR(e.mean, expected, 5.0 * e.stderr_ + 1e-3 * expected) << "stderr " << e.stderr_;
  EXPECT_TRUE(r.stats.features.area_lights);
}

/// An n³ grid, voxel 1/n, over [-0.5, 0.5]³: dense in one corner, thin elsewhere, with holes;
/// stored at index origin `shift` with the world origin moved back (the same cloth in the world).
std::string varying_grid_file(int n = 24, const std::array<int, 3>& shift = {0, 0, 0}) {
  const auto path = std::filesystem::temp_directory_path() /
                    fmt::format("weft_render_varying_grid_{}_{}_{}_{}.vdb", n, shift[0], shift[1], shift[2]);
  const double h = 1.0 / n;
  volume::Grid grid(h, "density");
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        if ((i + 2 * j + 3 * k) % 7 == 0) continue;  // holes
        grid.set_value(i + shift[0], j + shift[1], k + shift[2],
                       i < n / 2 && j < n / 2 ? 0.9f : 0.05f * static_cast<float>(1 + k % 3));
      }
  grid.set_origin({-0.5 - h * shift[0], -0.5 - h * shift[1], -0.5 - h * shift[2]});
  grid.save(path);
  return path.string();
}

// Delta tracking over the per-block majorant grid against the exact optical depth of the DDA on
// a strongly varying grid: two estimators, one answer.
TEST(GridMedium, MajorantGridDeltaTrackingEqualsOpticalDepthOnVaryingGrid) {
  const std::string file = varying_grid_file();
  const std::string medium = R"({{"type": "grid", "file": "{}", "sigma": 8, "albedo": 0.9, "tracking": "{}"}})";
  const RenderResult delta = render(scene_from(cube_scene(fmt::format(fmt::runtime(medium), file, "delta"), 64)));
  RenderOptions other_seed;
  other_seed.seed = 31;
  const RenderResult depth =
      render(scene_from(cube_scene(fmt::format(fmt::runtime(medium), file, "optical-depth"), 64)), other_seed);
  expect_same_image(delta.image, depth.image);
}

// The same cloth stored at another index origin (whole-voxel shifts that are not multiples of
// the majorant cells' 8 voxels, the world origin moved back) renders the same bytes with delta
// and ratio tracking: the majorant cells are anchored to the active voxels, not to the index
// lattice (docs/render.md §5 "Majorant cells anchored to the cloth"). Voxels of 1/32 keep every
// world position exact, so nothing but the anchoring could tell the two apart.
TEST(GridMedium, ShiftingTheIndexOriginRendersTheSameBytes) {
  const std::string medium = R"({{"type": "grid", "file": "{}", "sigma": 8, "albedo": 0.9, "tracking": "delta"}})";
  const RenderResult base = render(scene_from(cube_scene(fmt::format(fmt::runtime(medium), varying_grid_file(32)), 4)));
  for (const std::array<int, 3> shift : {std::array<int, 3>{5, -7, 13}, {-3, 1, 2}, {1001, -515, 37}}) {
    const RenderResult moved =
        render(scene_from(cube_scene(fmt::format(fmt::runtime(medium), varying_grid_file(32, shift)), 4)));
    EXPECT_EQ(moved.image.rgb, base.image.rgb) << shift[0] << "," << shift[1] << "," << shift[2];
    EXPECT_EQ(moved.stats.rays, base.stats.rays);
  }
}

// A path whose throughput is zero ends at once: an albedo-0 medium traced with roulette
// deferred to depth 100000 renders the bit-identical image of roulette from depth 0 (the only
// difference was wasted work on zero-throughput paths) with the same number of rays, for every
// medium kind.
TEST(DeadPaths, ZeroThroughputEndsThePathAtOnce) {
  const std::string grid = constant_grid_file();
  const std::vector<std::string> media{
      R"({"law": {"name": "exponential", "mu": 3}, "albedo": 0})",
      R"({"law": {"name": "gamma", "mean_extinction": 3, "alpha": 0.5}, "albedo": 0})",
      fmt::format(R"({{"type": "grid", "file": "{}", "sigma": 6, "albedo": 0}})", grid),
      fmt::format(R"({{"type": "grid", "file": "{}", "sigma": 6, "albedo": 0, "tracking": "optical-depth",
                     "law": {{"name": "gamma", "mean_extinction": 1, "alpha": 0.5}}}})",
                  grid)};
  for (const auto& medium : media) {
    std::string late = cube_scene(medium, 16);
    const std::string settings = R"("max_depth": 200, "rr_depth": 5)";
    ASSERT_NE(late.find(settings), std::string::npos);
    std::string early = late;
    late.replace(late.find(settings), settings.size(), R"("max_depth": 100000, "rr_depth": 100000)");
    early.replace(early.find(settings), settings.size(), R"("max_depth": 100000, "rr_depth": 0)");
    const RenderResult a = render(scene_from(late));
    const RenderResult b = render(scene_from(early));
    EXPECT_EQ(a.image.rgb, b.image.rgb) << medium;
    EXPECT_EQ(a.stats.rays, b.stats.rays) << medium;
    // Each path: one camera ray, at most one collision (then it ends), one shadow ray; far from
    // max_depth's 100000 events.
    EXPECT_LE(a.stats.rays, 4 * a.stats.paths) << medium;
  }
}

std::string ink_sphere_scene(const std::string& camera, const std::string& side, double mu) {
  return fmt::format(R"({{
    "camera": {{{}, "fov": 60, "width": 16, "height": 16}},
    "integrator": {{"spp": 64, "seed": 5}},
    "materials": {{"b": {{"type": "null"}}}},
    "media": {{"ink": {{"law": {{"name": "exponential", "mu": {}}}, "albedo": 0}}}},
    "shapes": [{{"type": "sphere", "radius": 1, "material": "b", "{}": "ink"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                     camera, mu, side);
}

// A camera inside a medium starts its paths in it (docs/scene-format.md "The camera's medium"):
// at the centre of an absorbing sphere every pixel is e^{-μ} (the radius is 1 in every direction).
TEST(CameraMedium, CameraInsideASphereSeesThroughItsMedium) {
  const double mu = 2.0;
  const RenderResult r =
      render(scene_from(ink_sphere_scene(R"("position": [0, 0, 0], "look_at": [0, 0, -1])", "interior", mu)));
  const Estimate e = region_mean(r.image, 0, 0, r.image.width, r.image.height);
  EXPECT_NEAR(e.mean, std::exp(-mu), 5.0 * e.stderr_ + kFloat);
}

// Outside a sphere whose exterior is an absorbing medium the camera is in that medium, which
// fills all space but the sphere: no path reaches the environment.
TEST(CameraMedium, CameraInAnExteriorMediumSeesNothing) {
  const RenderResult r =
      render(scene_from(ink_sphere_scene(R"("position": [0, 0, 3], "look_at": [0, 0, 0])", "exterior", 0.5)));
  EXPECT_EQ(*std::max_element(r.image.rgb.begin(), r.image.rgb.end()), 0.0F);
}

// Boundaries that contradict each other around the camera are an error, not a guess: inside the
// fog sphere but in front of a smaller sphere whose exterior is vacuum.
TEST(CameraMedium, ContradictoryBoundariesAreAnError) {
  const SceneDesc s = scene_from(R"({
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "width": 4, "height": 4},
    "materials": {"b": {"type": "null"}},
    "media": {"fog": {"law": {"name": "exponential", "mu": 1}}, "ink": {"law": {"name": "exponential", "mu": 1}}},
    "shapes": [{"type": "sphere", "radius": 3, "material": "b", "interior": "fog"},
               {"type": "sphere", "center": [0, 0, -1.5], "radius": 0.5, "material": "b", "interior": "ink"}],
    "lights": [{"type": "environment", "radiance": 1}]})");
  EXPECT_THAT([&] { (void)build_world(s); },
              weft::test::throws_one_line_error_with({"camera: its medium is ambiguous", "medium 'fog'"}));
}

// μ = 0 is a vacuum in every pair mode (docs/scene-format.md "Warnings"): it renders as one and
// says so. An exponential law is its own reciprocal partner, μ = 0 included.
TEST(ZeroExtinction, IsAVacuumWithAWarningInEveryMode) {
  for (const std::string mode : {"reciprocal", "same"}) {
    std::string text = furnace_scene(R"({"name": "exponential", "mu": 0})", mode, "source", 4);
    const World w = build_world(scene_from(text));
    EXPECT_EQ(world_warnings(w).size(), 1U) << mode;
    const RenderResult r = render(w);
    for (const float v : r.image.rgb) EXPECT_EQ(v, 1.0F) << mode;
  }
}

// A direction is a direction at any scale: an "up", a view or a light direction whose squared
// length underflows renders as its unit vector does (they were "parallel" or "zero", or NaN).
TEST(SceneDirections, TinyButNonZeroVectorsAreTheirUnitVectors) {
  const auto scene = [](const std::string& look_at, const std::string& up, const std::string& light) {
    return scene_from(fmt::format(R"({{
      "camera": {{"position": [0, 0, 0], "look_at": {}, "up": {}, "fov": 40, "width": 6, "height": 5}},
      "integrator": {{"spp": 2, "seed": 4}},
      "materials": {{"d": {{"type": "diffuse", "albedo": 0.5}}}},
      "shapes": [{{"type": "sphere", "center": [0.3, 0.2, -3], "radius": 1, "material": "d"}}],
      "lights": [{{"type": "directional", "direction": {}, "irradiance": 2}}]}})",
                                  look_at, up, light));
  };
  const Image unit = render(scene("[0, 0, -1]", "[0, 1, 0]", "[0.2, -1, -0.3]")).image;
  const Image tiny = render(scene("[0, 0, -1e-300]", "[0, 1e-300, 0]", "[2e-301, -1e-300, -3e-301]")).image;
  EXPECT_EQ(unit.rgb, tiny.rgb);
  EXPECT_GT(*std::max_element(unit.rgb.begin(), unit.rgb.end()), 0.0F);
  EXPECT_THAT([&] { (void)scene("[0, 0, -1]", "[0, 0, 0]", "[0, -1, 0]"); },
              weft::test::throws_one_line_error_with({"'up' must not be zero"}));
  EXPECT_THAT([&] { (void)scene("[0, 0, -1]", "[0, 0, 1e-300]", "[0, -1, 0]"); },
              weft::test::throws_one_line_error_with({"'up' is parallel"}));
  // Parallel but for rounding: `up` written as look_at − position, which doubles compute as
  // (−1.8, 0.22000000000000003, −1.2), left the roll to rounding; refused within 1e-6 rad, taken
  // beyond it.
  const auto camera = [](const std::string& up) {
    return scene_from(fmt::format(R"({{
      "camera": {{"position": [2.6, 0.3, 1.2], "look_at": [0.8, 0.52, 0.0], "up": {}, "width": 4, "height": 4}},
      "lights": [{{"type": "environment", "radiance": 1}}]}})",
                                  up));
  };
  EXPECT_THAT([&] { (void)camera("[-1.8, 0.22, -1.2]"); },
              weft::test::throws_one_line_error_with({"'up' is parallel to the view direction", "under 1e-6"}));
  const Eigen::Vector3d d = Eigen::Vector3d(-1.8, 0.22, -1.2).normalized();
  const Eigen::Vector3d p = Eigen::Vector3d(0.0, 1.2, 0.22).normalized();  // ⟂ d
  const auto off = [&](double angle) {
    const Eigen::Vector3d up = std::cos(angle) * d + std::sin(angle) * p;
    return fmt::format("[{:.17g}, {:.17g}, {:.17g}]", up.x(), up.y(), up.z());
  };
  EXPECT_THAT([&] { (void)camera(off(1e-7)); }, weft::test::throws_one_line_error_with({"'up' is parallel"}));
  EXPECT_NO_THROW((void)camera(off(1e-5)));
}

// A scene with nothing that emits renders black, and says so; one light is enough to silence it.
TEST(SceneWarnings, ASceneWithoutLightSaysItsImageIsBlack) {
  const std::string dark = R"({
    "camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "width": 4, "height": 4},
    "materials": {"d": {"type": "diffuse", "albedo": 0.5}},
    "shapes": [{"type": "sphere", "radius": 1, "material": "d"}]})";
  const World w = build_world(scene_from(dark));
  const std::vector<std::string> warnings = world_warnings(w);
  ASSERT_EQ(warnings.size(), 1U);
  EXPECT_NE(warnings[0].find("no light"), std::string::npos) << warnings[0];
  for (const float v : render(w).image.rgb) EXPECT_EQ(v, 0.0F);
  std::string lit = dark;
  lit.insert(lit.rfind('}'), R"(, "lights": [{"type": "point", "position": [0, 2, 2], "intensity": 1}])");
  EXPECT_TRUE(world_warnings(build_world(scene_from(lit))).empty());
  // Lights that are there but emit nothing make the same black image: said too.
  std::string off = dark;
  off.insert(off.rfind('}'), R"(, "lights": [{"type": "point", "position": [0, 2, 2], "intensity": 0},
                                             {"type": "directional", "direction": [0, -1, 0], "irradiance": 0}])");
  const std::vector<std::string> off_warnings = world_warnings(build_world(scene_from(off)));
  ASSERT_EQ(off_warnings.size(), 1U);
  EXPECT_NE(off_warnings[0].find("emits nothing"), std::string::npos) << off_warnings[0];
}

// A medium bounded by a surface with no inside fills the space behind it: said, for a rectangle
// and an open mesh (a lone triangle), not for a box, a sphere or a closed mesh (a tetrahedron,
// its vertices written once per face: joined by position).
TEST(SceneWarnings, AMediumBoundedByAnOpenSurfaceIsSaid) {
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("weft-open-boundary-{}", ::getpid());
  std::filesystem::create_directories(dir);
  {
    std::ofstream(dir / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    // A tetrahedron with its vertices once per face; one with a face flipped; two sharing an edge
    // (four triangles on it: closed).
    const char* v[6] = {"0 0 0", "1 0 0", "0 1 0", "0 0 1", "1 1 -1", "2 2 1"};
    const auto write = [&](const std::filesystem::path& file, const std::vector<std::array<int, 3>>& faces) {
      std::ofstream out(file);
      int n = 0;
      for (const auto& f : faces) {
        for (const int k : f) out << "v " << v[k] << "\n";
        out << "f " << n + 1 << " " << n + 2 << " " << n + 3 << "\n";
        n += 3;
      }
    };
    write(dir / "tet.obj", {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
    write(dir / "flipped.obj", {{0, 1, 2}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
    // The second tetrahedron (1, 2, 4, 5), wound the same way, shares edge 1–2 with the first.
    write(dir / "two.obj", {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {1, 4, 2}, {1, 2, 5}, {1, 5, 4}, {2, 4, 5}});
  }
  const auto warnings_of = [&](const std::string& shape) {
    return world_warnings(build_world(parse_scene(fmt::format(R"({{
      "camera": {{"position": [0.3, 0.3, 3], "look_at": [0.3, 0.3, 0], "width": 4, "height": 4}},
      "materials": {{"b": {{"type": "null"}}}},
      "media": {{"m": {{"law": {{"name": "exponential", "mu": 0.5}}, "albedo": 0}}}},
      "shapes": [{}],
      "lights": [{{"type": "environment", "radiance": 1}}]}})",
                                                              shape),
                                                  "open boundary", dir)));
  };
  const std::vector<std::string> rect = warnings_of(
      R"({"type": "rectangle", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [0, 1, 0], "material": "b", "interior": "m"})");
  ASSERT_EQ(rect.size(), 1U);
  EXPECT_NE(rect[0].find("shapes[0] (a rectangle) is the interior of medium 'm' but is not closed"), std::string::npos)
      << rect[0];
  const std::vector<std::string> tri =
      warnings_of(R"({"type": "mesh", "file": "tri.obj", "material": "b", "exterior": "m"})");
  ASSERT_EQ(tri.size(), 1U);
  EXPECT_NE(tri[0].find("(a mesh) is the exterior of medium 'm' but is not closed (an edge of one triangle)"),
            std::string::npos)
      << tri[0];
  EXPECT_TRUE(warnings_of(R"({"type": "mesh", "file": "tet.obj", "material": "b", "interior": "m"})").empty());
  const std::vector<std::string> flipped =
      warnings_of(R"({"type": "mesh", "file": "flipped.obj", "material": "b", "interior": "m"})");
  EXPECT_TRUE(warnings_of(R"({"type": "mesh", "file": "two.obj", "material": "b", "interior": "m"})").empty());
  ASSERT_EQ(flipped.size(), 1U);
  EXPECT_NE(flipped[0].find("some of its triangles are wound against their neighbours"), std::string::npos)
      << flipped[0];
  EXPECT_TRUE(
      warnings_of(R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "material": "b", "interior": "m"})").empty());
  std::filesystem::remove_all(dir);
}

// An environment image that is black, or scaled by 0, lights nothing.
TEST(EnvironmentMap, EmitsOnlyWithALitPixelAndAScaleAboveZero) {
  EXPECT_TRUE(EnvironmentMap(2, 1, {0, 0, 0, 0, 0.5F, 0}, 1.0).emits());
  EXPECT_FALSE(EnvironmentMap(2, 1, {0, 0, 0, 0, 0, 0}, 1.0).emits());
  EXPECT_FALSE(EnvironmentMap(2, 1, {0, 0, 0, 0, 0.5F, 0}, 0.0).emits());
}

// An EXR holds finite pixels only: a mean beyond float's range is refused with its count, and
// neither file is written.
TEST(ImageFiles, NonFinitePixelsAreRefused) {
  Image im;
  im.width = 2;
  im.height = 1;
  im.spp = 1;
  im.rgb = {1.0F, 1.0F, 1.0F, std::numeric_limits<float>::infinity(), 0.0F, 0.0F};
  const std::filesystem::path exr = std::filesystem::temp_directory_path() / fmt::format("weft-inf-{}.exr", ::getpid());
  std::filesystem::path png = exr;
  png.replace_extension(".png");
  EXPECT_THAT([&] { write_exr_and_png(exr, png, im, 1.0); },
              ::testing::ThrowsMessage<Error>(::testing::HasSubstr("1 of 2 pixels are not finite")));
  EXPECT_FALSE(std::filesystem::exists(exr));
  EXPECT_FALSE(std::filesystem::exists(png));
  EXPECT_THROW(write_exr(exr, im), Error);
}

// A PNG that does not fit on the disk (here past a file size limit) is one error naming it, with
// nothing printed besides (libpng and VTK had their own lines), and no file under its name.
TEST(ImageFiles, ShortPngWriteIsOneErrorAndNoChatter) {
  Image im;
  im.width = im.height = 256;
  im.spp = 1;
  im.rgb.resize(std::size_t{3} * static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height));
  for (std::size_t i = 0; i < im.rgb.size(); ++i) im.rgb[i] = static_cast<float>((i * 2654435761U) % 1000) / 1000.0F;
  const std::filesystem::path png =
      std::filesystem::temp_directory_path() / fmt::format("weft-short-{}.png", ::getpid());
  std::string message;
  testing::internal::CaptureStderr();
  {
    const test::FileSizeLimit limit(1024);
    try {
      write_png(png, im, 1.0);
    } catch (const Error& e) {
      message = e.what();
    }
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_THAT(message, ::testing::HasSubstr("cannot write '" + png.string() + "'"));
  EXPECT_EQ(printed, "");
  EXPECT_FALSE(std::filesystem::exists(png));
}

}  // namespace
}  // namespace weft::render
