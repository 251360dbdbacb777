// Every medium kind through the one Medium interface (medium.h): a white furnace (a closed
// index-matched cube of a conservative medium under a uniform environment of radiance 1 renders
// 1: in reciprocal mode every full path has weight 1, docs/render.md §2) and an absorbing slab
// (each pixel is the pixel-average of T_Q of the chord's optical depth), for homogeneous laws,
// the new gap-gamma and gamma-mixture laws, delta-tracked and optical-depth grids and a constant
// local-gamma field. Tolerances: 5 standard errors of the rendered estimate plus float rounding.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "weft/core/error.h"
#include "weft/render/medium.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::render {
namespace {

/// What a render of `scene` specialises on: the features of its built world.
Features features_of_scene(const SceneDesc& scene) { return build_world(scene).features; }

namespace fs = std::filesystem;

/// 10³ voxels of concentration 0.5 over [-0.5, 0.5]³ (σ = 6 makes μ = 3).
std::string constant_grid() {
  const fs::path path = fs::temp_directory_path() / "weft_media_kinds_grid.vdb";
  volume::Grid grid(0.1, "density");
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k) grid.set_value(i, j, k, 0.5f);
  grid.set_origin({-0.5, -0.5, -0.5});
  grid.save(path);
  return path.string();
}

/// The same cube as three per-axis grids of a direction-dependent extinction (docs/render.md §6d):
/// 0.2 along x, 0.8 along y, 0.5 along z, so a view along z sees μ = 3 as the constant grid.
std::string axis_grids() {
  const fs::path path = fs::temp_directory_path() / "weft_media_kinds_axes.vdb";
  std::vector<volume::Grid> grids;
  for (const auto& [name, v] : {std::pair<std::string, float>{"cx", 0.2f}, {"cy", 0.8f}, {"cz", 0.5f}}) {
    volume::Grid g(0.1, name);
    for (int i = 0; i < 10; ++i)
      for (int j = 0; j < 10; ++j)
        for (int k = 0; k < 10; ++k) g.set_value(i, j, k, v);
    g.set_origin({-0.5, -0.5, -0.5});
    grids.push_back(g);
  }
  volume::save_grids(grids, path);
  return path.string();
}

/// Local-gamma fields of one coarse voxel over [-0.5, 0.5]³: C̄ = 0.5, V = 0.1 (α = 2.5).
std::string constant_fields() {
  const fs::path path = fs::temp_directory_path() / "weft_media_kinds_fields.vdb";
  std::vector<volume::Grid> grids;
  for (const std::string name :
       {"mean_concentration", "var_concentration_x", "var_concentration_y", "var_concentration_z"}) {
    volume::Grid g(1.0, name);
    g.set_value(0, 0, 0, name == "mean_concentration" ? 0.5f : 0.1f);
    g.set_origin({-0.5, -0.5, -0.5});
    grids.push_back(g);
  }
  volume::save_grids(grids, path);
  return path.string();
}

struct Kind {
  std::string label;
  std::string medium;    ///< JSON with "{albedo}" where the albedo goes
  std::string kind;      ///< expected MediumTraits::kind
  std::string describe;  ///< expected start of the run summary's description (kind, law, estimator)
};

std::vector<Kind> kinds() {
  const std::string grid = constant_grid();
  const std::string fields = constant_fields();
  return {
      {"exponential", R"({"law": {"name": "exponential", "mu": 3}, "albedo": ALBEDO})", "homogeneous",
       "homogeneous medium, exponential law, closed-form flights"},
      {"gamma", R"({"law": {"name": "gamma", "mean_extinction": 3, "alpha": 0.5}, "albedo": ALBEDO})", "homogeneous",
       "homogeneous medium, gamma law, T_Q/T_S flights ("},
      {"gap_gamma",
       R"({"law": {"name": "gap-gamma", "gap": 0.2, "mean_extinction": 3, "alpha": 1.5}, "albedo": ALBEDO})",
       "homogeneous", "homogeneous medium, gap-gamma law, T_Q/T_S flights ("},
      {"gamma_mixture",
       R"({"law": {"name": "gamma-mixture", "weight_1": 0.3, "alpha_1": 1, "mean_extinction_1": 1,
                   "weight_2": 0.7, "alpha_2": 3, "mean_extinction_2": 4}, "albedo": ALBEDO})",
       "homogeneous", "homogeneous medium, gamma-mixture law, T_Q/T_S flights ("},
      {"grid_delta", fmt::format(R"({{"type": "grid", "file": "{}", "sigma": 6, "albedo": ALBEDO}})", grid), "grid",
       "grid medium, exponential law, delta + ratio tracking"},
      {"grid_directional",
       fmt::format(R"({{"type": "grid", "file": "{}", "axis_grids": ["cx", "cy", "cz"], "sigma": 6,
                       "albedo": ALBEDO}})",
                   axis_grids()),
       "grid", "grid medium, exponential law, delta + ratio tracking, direction-dependent extinction"},
      {"grid_optical_depth_gamma",
       fmt::format(R"({{"type": "grid", "file": "{}", "sigma": 6, "tracking": "optical-depth", "albedo": ALBEDO,
                       "law": {{"name": "gamma", "mean_extinction": 1, "alpha": 0.5}}}})",
                   grid),
       "grid", "grid medium, gamma law, optical-depth flights (exact DDA)"},
      {"local_gamma", fmt::format(R"({{"type": "local-gamma", "fields": "{}", "sigma": 6, "albedo": ALBEDO}})", fields),
       "local-gamma", "local-gamma medium, per-voxel gamma law, hazard inversion, optical-depth memory"},
  };
}

std::string with_albedo(std::string medium, const std::string& albedo) {
  medium.replace(medium.find("ALBEDO"), 6, albedo);
  return medium;
}

class MediaKinds : public ::testing::TestWithParam<Kind> {};

// The run summary tells the truth: each medium is named with its kind, law and
// estimator as the medium itself reports them, and only a homogeneous exponential medium lets
// the exponential specialisation run.
TEST_P(MediaKinds, FeaturesNameEachMediumsKindLawAndEstimator) {
  const Kind& k = GetParam();
  const SceneDesc scene = parse_scene(fmt::format(R"({{
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {}}},
    "shapes": [{{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "boundary",
                 "interior": "m"}}]
  }})",
                                                  with_albedo(k.medium, "0.5")),
                                      "features " + k.label, ".");
  const Features f = features_of_scene(scene);
  ASSERT_EQ(f.media_described.size(), 1U);
  const std::string expected = "medium 'm': " + k.describe;
  EXPECT_EQ(f.media_described[0].substr(0, expected.size()), expected) << f.media_described[0];
  const auto names = f.names();
  EXPECT_NE(std::find(names.begin(), names.end(), f.media_described[0]), names.end());
  EXPECT_EQ(f.general_media, k.label != "exponential") << k.label;
  EXPECT_EQ(f.heterogeneous, k.kind != "homogeneous") << k.label;
  EXPECT_FALSE(f.non_reciprocal) << k.label;
  // The local-gamma medium is its own kind: no law name rides on its description.
  if (k.kind == "local-gamma") {
    EXPECT_TRUE(scene.media.at("m").law.name.empty());
  }
}

TEST(MediaKindsSummary, SameModeNamesItsPathWeightsAndNoPseudoLawExists) {
  const SceneDesc scene = parse_scene(R"({
    "materials": {"boundary": {"type": "null"}},
    "media": {"m": {"law": {"name": "gamma", "mean_extinction": 3, "alpha": 0.5}, "mode": "same"}},
    "shapes": [{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "boundary",
                "interior": "m"}]
  })",
                                      "same mode", ".");
  const Features f = features_of_scene(scene);
  ASSERT_EQ(f.media_described.size(), 1U);
  EXPECT_NE(f.media_described[0].find("T_S/(c·p_Q) path weights"), std::string::npos) << f.media_described[0];
  EXPECT_TRUE(f.non_reciprocal);
  // The old placeholder "gamma-field" is no law of the registry: a medium naming it is refused.
  EXPECT_THROW((void)build_medium(parse_scene(R"({"media": {"m": {"law": "gamma-field"}}})", "pseudo law", "."), "m"),
               Error);
}

// α = ∞ (an exponential component: a zero-variance group of the across-beam model) is "inf" in
// scene files, written by scene_to_json and read back into the same law.
TEST(MediaKindsSummary, InfiniteAlphaIsWrittenAsInfAndReadBack) {
  const std::string text = R"({"media": {"m": {"law": {"name": "gamma-mixture", "weight_1": 0.4, "alpha_1": 2,
      "mean_extinction_1": 1.5, "weight_2": 0.6, "alpha_2": "inf", "mean_extinction_2": 3}}}})";
  const SceneDesc a = parse_scene(text, "inf alpha", ".");
  EXPECT_EQ(a.media.at("m").law.params.at("alpha_2"), std::numeric_limits<double>::infinity());
  const std::string json = scene_to_json(a);
  EXPECT_NE(json.find(R"("alpha_2": "inf")"), std::string::npos) << json;
  const SceneDesc b = parse_scene(json, "round trip", ".");
  const auto pair = make_medium_pair(b.media.at("m"), "m");
  for (const double t : {0.1, 0.5, 2.0}) {
    const double expected = 0.4 * std::pow(1.0 + 1.5 * t / 2.0, -2.0) + 0.6 * std::exp(-3.0 * t);
    EXPECT_NEAR(pair.law(transmittance::Origin::source).transmittance(t), expected, 1e-12) << t;
  }
  // Other strings stay errors.
  EXPECT_THROW((void)parse_scene(R"({"media": {"m": {"law": {"name": "gamma", "alpha": "big",
      "mean_extinction": 1}}}})",
                                 "bad", "."),
               Error);
}

TEST_P(MediaKinds, WhiteFurnaceRendersOne) {
  const Kind& k = GetParam();
  const SceneDesc scene = parse_scene(fmt::format(R"({{
    "camera": {{"position": [0, 0, 3.2], "look_at": [0, 0, 0], "fov": 30, "width": 12, "height": 12}},
    "integrator": {{"spp": 64, "max_depth": 100000, "rr_depth": 100000, "seed": 3}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {}}},
    "shapes": [{{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "boundary",
                 "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                                                  with_albedo(k.medium, "1")),
                                      "furnace " + k.label, ".");
  EXPECT_EQ(build_medium(scene, "m")->traits().kind, k.kind);
  const RenderResult r = render(scene);
  // The cube covers the central 4x4 pixels.
  double sum = 0.0;
  double var = 0.0;
  for (int y = 4; y < 8; ++y)
    for (int x = 4; x < 8; ++x) {
      sum += r.image.at(x, y, 0);
      var += r.image.var_at(x, y, 0);
    }
  const double mean = sum / 16.0;
  const double se = std::sqrt(var) / 16.0;
  EXPECT_NEAR(mean, 1.0, 5.0 * se + 1e-5) << k.label << " stderr " << se;
  EXPECT_GT(se, 0.0) << "the medium must have been sampled";
  EXPECT_EQ(r.stats.invalid_samples, 0U);
}

// An absorbing cube seen straight on through its front face: the central pixel's rays cross
// the full 1-unit depth, so it is T_Q of that chord (τ = 3 for every kind here except the
// laws' own scaling), compared with the pair's own T_Q (homogeneous and optical-depth kinds)
// or e^{−3} (delta-tracked grid) or the local gamma law (1 + σt/β)^{−α}, α = 2.5, β = 5.
TEST_P(MediaKinds, AbsorbingCubeShowsSourceTransmittance) {
  const Kind& k = GetParam();
  const SceneDesc scene = parse_scene(fmt::format(R"({{
    "camera": {{"position": [0, 0, 40], "look_at": [0, 0, 0], "fov": 0.2, "width": 3, "height": 3}},
    "integrator": {{"spp": 512, "seed": 5}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {}}},
    "shapes": [{{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "boundary",
                 "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                                                  with_albedo(k.medium, "0")),
                                      "slab " + k.label, ".");
  const MediumDesc& desc = scene.media.at("m");
  double expected = 0.0;
  if (desc.kind == MediumKind::local_gamma) {
    expected = std::pow(1.0 + 6.0 * 1.0 / 5.0, -2.5);
  } else {
    const double tau = desc.kind == MediumKind::grid ? 3.0 : 1.0;  // grids: law in τ = σC·t
    expected = make_medium_pair(desc, "m").transmittance(transmittance::Origin::source, tau);
  }
  const RenderResult r = render(scene);
  const double se = std::sqrt(r.image.var_at(1, 1, 0));
  EXPECT_NEAR(r.image.at(1, 1, 0), expected, 5.0 * se + 1e-4) << k.label;
}

INSTANTIATE_TEST_SUITE_P(EveryKind, MediaKinds, ::testing::ValuesIn(kinds()),
                         [](const auto& info) { return info.param.label; });

}  // namespace
}  // namespace weft::render
