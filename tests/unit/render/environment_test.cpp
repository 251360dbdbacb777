// Image environment light: the importance sampler against its own density (normalisation over
// the sphere, χ² of sample counts per pixel), and renders against the constant environment and
// closed forms. Statistical tolerances are 5 standard errors; seeds are fixed.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/render/environment.h"
#include "weft/render/image.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"

namespace weft::render {
namespace {
namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

/// A 16×8 lat-long image with a hot spot, a black row band and smooth variation elsewhere.
EnvironmentMap test_map(std::vector<float>* pixels = nullptr) {
  const int w = 16;
  const int h = 8;
  std::vector<float> rgb(static_cast<std::size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * w + x) * 3;
      double v = 0.2 + 0.1 * std::sin(0.7 * x) * std::sin(0.7 * x) + 0.05 * y;
      if (y == 5) v = 0.0;             // a black band: never sampled
      if (x == 3 && y == 2) v = 40.0;  // the sun
      if (x == 12 && y == 0) v = 5.0;  // near the pole, where sin θ is small
      rgb[i] = static_cast<float>(v);
      rgb[i + 1] = static_cast<float>(0.5 * v);
      rgb[i + 2] = static_cast<float>(2.0 * v);
    }
  if (pixels != nullptr) *pixels = rgb;
  return {w, h, rgb, 1.5};
}

/// ∫ over pixel (x, y) of the solid-angle pdf, by the midpoint rule on a fine grid aligned with
/// the pixel (the pdf varies as 1/sin θ inside it).
double pixel_probability(const EnvironmentMap& map, int x, int y, int sub) {
  double sum = 0.0;
  const double du = 1.0 / (map.width() * sub);
  const double dv = 1.0 / (map.height() * sub);
  for (int j = 0; j < sub; ++j) {
    const double v0 = (y * sub + j) * dv;
    const double v1 = v0 + dv;
    // Solid angle of the sub-cell: Δφ·(cos θ0 − cos θ1).
    const double solid = 2.0 * kPi * du * (std::cos(kPi * v0) - std::cos(kPi * v1));
    for (int i = 0; i < sub; ++i) {
      const double u = (x * sub + i + 0.5) * du;
      sum += map.pdf(EnvironmentMap::direction(u, 0.5 * (v0 + v1))) * solid;
    }
  }
  return sum;
}

TEST(EnvironmentMap, DirectionAndCoordinatesAreInverse) {
  for (double u : {0.01, 0.25, 0.5, 0.75, 0.99})
    for (double v : {0.02, 0.3, 0.5, 0.9}) {
      double uu = 0.0;
      double vv = 0.0;
      EnvironmentMap::coordinates(EnvironmentMap::direction(u, v), uu, vv);
      EXPECT_NEAR(uu, u, 1e-12);
      EXPECT_NEAR(vv, v, 1e-12);
    }
  EXPECT_NEAR((EnvironmentMap::direction(0.5, 0.0) - Vec3(0, 1, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((EnvironmentMap::direction(0.5, 0.5) - Vec3(0, 0, -1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((EnvironmentMap::direction(0.75, 0.5) - Vec3(1, 0, 0)).norm(), 0.0, 1e-12);
}

TEST(EnvironmentMap, PdfIntegratesToOneOverTheSphere) {
  const EnvironmentMap map = test_map();
  double total = 0.0;
  for (int y = 0; y < map.height(); ++y)
    for (int x = 0; x < map.width(); ++x) total += pixel_probability(map, x, y, 32);
  // Midpoint rule error on 1/sin θ over 32 sub-rows per pixel is far below 1e-3.
  EXPECT_NEAR(total, 1.0, 1e-3);
  EXPECT_NEAR(pixel_probability(map, 7, 5, 4), 0.0, 0.0) << "black pixels have zero density";
}

TEST(EnvironmentMap, SamplesFollowThePdf) {
  const EnvironmentMap map = test_map();
  const int w = map.width();
  const int h = map.height();
  std::vector<double> counts(static_cast<std::size_t>(w) * h, 0.0);
  const int n = 200000;
  Pcg32 rng = stream_for(42, 0);
  double max_rel_pdf_error = 0.0;
  for (int k = 0; k < n; ++k) {
    const double xi1 = rng.uniform();
    const EnvironmentMap::Sample s = map.sample(xi1, rng.uniform());
    ASSERT_GT(s.pdf, 0.0);
    // The density reported with a sample is the one pdf() gives for its direction.
    max_rel_pdf_error = std::max(max_rel_pdf_error, std::abs(map.pdf(s.wi) / s.pdf - 1.0));
    // ... and its radiance is the image's.
    EXPECT_NEAR((map.radiance(s.wi) - s.radiance).abs().maxCoeff(), 0.0, 1e-12);
    double u = 0.0;
    double v = 0.0;
    EnvironmentMap::coordinates(s.wi, u, v);
    const int x = std::min(w - 1, static_cast<int>(u * w));
    const int y = std::min(h - 1, static_cast<int>(v * h));
    counts[static_cast<std::size_t>(y) * w + x] += 1.0;
  }
  EXPECT_LT(max_rel_pdf_error, 1e-6);
  // Pearson χ² over pixels with non-zero expected count; 5σ of the χ² distribution
  // (mean dof, variance 2 dof).
  double chi2 = 0.0;
  int dof = -1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double expected = n * pixel_probability(map, x, y, 32);
      const double observed = counts[static_cast<std::size_t>(y) * w + x];
      if (expected <= 0.0) {
        EXPECT_EQ(observed, 0.0) << "sample in a zero-density pixel " << x << "," << y;
        continue;
      }
      chi2 += (observed - expected) * (observed - expected) / expected;
      ++dof;
    }
  EXPECT_LT(chi2, dof + 5.0 * std::sqrt(2.0 * dof)) << "dof " << dof;
}

TEST(Distribution2D, RejectsNegativeCellsAndHandlesAllZero) {
  EXPECT_THROW(Distribution2D({1.0, -1.0}, 2, 1), Error);
  const Distribution2D zero({0.0, 0.0, 0.0, 0.0}, 2, 2);
  EXPECT_EQ(zero.integral(), 0.0);
  EXPECT_EQ(zero.sample(0.3, 0.7).pdf, 0.0);
  EXPECT_EQ(zero.pdf(0.3, 0.7), 0.0);
}

class EnvironmentScene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("weft_render_env_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  /// Writes a w×h lat-long EXR whose pixel (x, y) is value(x, y) (grey).
  template <typename F>
  fs::path exr(const std::string& name, int w, int h, F value) const {
    Image im;
    im.width = w;
    im.height = h;
    im.rgb.resize(static_cast<std::size_t>(w) * h * 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c)
          im.rgb[(static_cast<std::size_t>(y) * w + x) * 3 + c] = static_cast<float>(value(x, y));
    const fs::path p = dir_ / name;
    write_exr(p, im);
    return p;
  }
  fs::path dir_;
};

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

/// A diffuse sphere on a diffuse floor under an environment light.
std::string sphere_scene(const std::string& light) {
  return fmt::format(R"({{
    "camera": {{"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "fov": 40, "width": 16, "height": 12}},
    "integrator": {{"spp": 64, "max_depth": 8, "rr_depth": 3, "seed": 9}},
    "materials": {{"white": {{"albedo": 0.6}}}},
    "shapes": [{{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "white"}},
               {{"type": "rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6], "material": "white"}}],
    "lights": [{}]
  }})",
                     light);
}

// A constant image is the constant environment: same image within noise (independent
// estimators: the image env samples by its map, the constant one uniformly).
TEST_F(EnvironmentScene, ConstantImageEqualsConstantEnvironment) {
  const fs::path sky = exr("sky.exr", 32, 16, [](int, int) { return 0.8; });
  const Image a = render(parse_scene(sphere_scene(R"({"type": "environment", "radiance": 1.2})"), "a", dir_)).image;
  const RenderResult rb =
      render(parse_scene(sphere_scene(R"({"type": "environment", "image": "sky.exr", "scale": 1.5})"), "b", dir_));
  const Image& b = rb.image;
  EXPECT_TRUE(rb.stats.features.environment_image);
  double z2 = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const double var = a.variance[i] + b.variance[i];
    if (var <= 0.0) {
      EXPECT_NEAR(a.rgb[i], b.rgb[i], 1e-5 * (1.0 + a.rgb[i]));
      continue;
    }
    z2 += (a.rgb[i] - b.rgb[i]) * (a.rgb[i] - b.rgb[i]) / var;
    ++n;
  }
  ASSERT_GT(n, 100);
  // Mean of z² is 1 for equal expectations; its standard error is about √(2/n).
  EXPECT_LT(z2 / n, 1.0 + 5.0 * std::sqrt(2.0 / n));
  const Estimate ea = region_mean(a, 0, 0, a.width, a.height);
  const Estimate eb = region_mean(b, 0, 0, b.width, b.height);
  EXPECT_NEAR(ea.mean, eb.mean, 5.0 * std::hypot(ea.stderr_, eb.stderr_));
}

// White furnace with an image environment of constant 1: a closed null-bounded sphere of a
// conservative gamma-law medium renders 1 (NEE by the map's sampler, MIS with phase sampling).
TEST_F(EnvironmentScene, FurnaceWithConstantImageRendersOne) {
  const fs::path one = exr("one.exr", 16, 8, [](int, int) { return 1.0; });
  const std::string scene = R"({
    "camera": {"position": [0, 0, 3.2], "look_at": [0, 0, 0], "fov": 30, "width": 12, "height": 12},
    "integrator": {"spp": 96, "max_depth": 100000, "rr_depth": 100000, "seed": 3},
    "materials": {"boundary": {"type": "null"}},
    "media": {"m": {"law": {"name": "gamma", "mean_extinction": 3, "alpha": 2}, "albedo": 1, "g": 0.3}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "boundary", "interior": "m"}],
    "lights": [{"type": "environment", "image": "one.exr"}]
  })";
  const RenderResult r = render(parse_scene(scene, "furnace", dir_));
  const Estimate e = region_mean(r.image, 3, 3, 9, 9);
  EXPECT_NEAR(e.mean, 1.0, 5.0 * e.stderr_ + 1e-5) << "stderr " << e.stderr_;
  EXPECT_GT(e.stderr_, 0.0);
  EXPECT_EQ(r.stats.invalid_samples, 0U);
}

// Sky of radiance L above the horizon, black below (rows split at the horizon): a Lambertian
// floor of albedo ρ facing up receives E = πL and reflects ρL. Importance sampling never
// proposes the black half, and MIS with cosine sampling must still give the exact answer.
TEST_F(EnvironmentScene, UpperHemisphereSkyLightsAFloorToAlbedoTimesRadiance) {
  const fs::path sky = exr("half.exr", 32, 16, [](int, int y) { return y < 8 ? 2.0 : 0.0; });
  const std::string scene = R"({
    "camera": {"position": [0, 3, 0.001], "look_at": [0, 0, 0], "fov": 30, "width": 8, "height": 8},
    "integrator": {"spp": 64, "max_depth": 1, "seed": 4},
    "materials": {"floor": {"albedo": 0.5}},
    "shapes": [{"type": "rectangle", "corner": [-50, 0, 50], "edge_u": [100, 0, 0], "edge_v": [0, 0, -100],
                "material": "floor"}],
    "lights": [{"type": "environment", "image": "half.exr", "scale": 1}]
  })";
  const RenderResult r = render(parse_scene(scene, "sky", dir_));
  const Estimate e = region_mean(r.image, 0, 0, 8, 8);
  EXPECT_NEAR(e.mean, 0.5 * 2.0, 5.0 * e.stderr_ + 1e-5) << "stderr " << e.stderr_;
}

TEST_F(EnvironmentScene, BadImageInputIsOneLineError) {
  auto error_of = [&](const std::string& light) -> std::string {
    try {
      // Images are read when the world is built (render/world), still before any render.
      (void)build_world(parse_scene(fmt::format(R"({{"lights": [{}]}})", light), "s", dir_));
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  const std::string missing = error_of(R"({"type": "environment", "image": "nope.exr"})");
  EXPECT_NE(missing.find("nope.exr"), std::string::npos) << missing;
  exr("neg.exr", 4, 2, [](int x, int) { return x == 1 ? -1.0 : 1.0; });
  const std::string negative = error_of(R"({"type": "environment", "image": "neg.exr"})");
  EXPECT_NE(negative.find("neg.exr"), std::string::npos) << negative;
  EXPECT_NE(negative.find(">= 0"), std::string::npos) << negative;
  {
    std::ofstream out(dir_ / "junk.exr");
    out << "not an exr";
  }
  const std::string junk = error_of(R"({"type": "environment", "image": "junk.exr"})");
  EXPECT_NE(junk.find("junk.exr"), std::string::npos) << junk;
  exr("ok.exr", 4, 2, [](int, int) { return 1.0; });
  const std::string both = error_of(R"({"type": "environment", "image": "ok.exr", "radiance": 1})");
  EXPECT_NE(both.find("not both"), std::string::npos) << both;
  const std::string bad_scale = error_of(R"({"type": "environment", "image": "ok.exr", "scale": -1})");
  EXPECT_NE(bad_scale.find("scale"), std::string::npos) << bad_scale;
  for (const auto& e : {missing, negative, junk, both, bad_scale}) {
    EXPECT_FALSE(e.empty());
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST_F(EnvironmentScene, ImageEnvironmentRoundTripsThroughJson) {
  exr("sky.exr", 8, 4, [](int x, int y) { return 0.1 * (x + y); });
  const SceneDesc a =
      parse_scene(R"({"lights": [{"type": "environment", "image": "sky.exr", "scale": 2.5}]})", "env", dir_);
  const std::string once = scene_to_json(a);
  const SceneDesc b = parse_scene(once, "env (written)", ".");
  EXPECT_EQ(scene_to_json(b), once);
  ASSERT_EQ(b.lights.size(), 1U);
  EXPECT_EQ(fs::path(b.lights[0].image), dir_ / "sky.exr");
  EXPECT_DOUBLE_EQ(b.lights[0].scale, 2.5);
}

}  // namespace
}  // namespace weft::render
