// The memory rules of the local-gamma medium across coarse cells (docs/render.md §5e), each on
// the fields where its answer is derived:
//  - a varying field's white furnace renders 1 under every rule (flights and shadows are one law);
//  - an albedo-0 image of fields made from a separable fine grid C = m(z)·U (U one gamma
//    variable per column, m changing along the ray) against the fine grid's exact mean
//    transmittance: optical-depth and carried are exact there (the law in τ), segment is too
//    transparent and renewal too opaque, each by many standard errors;
//  - the seam test: the same statistics in cells of half the size change nothing for segment,
//    optical-depth and carried, and change renewal.
#include <boost/math/distributions/gamma.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "error_matchers.h"
#include "image_mean.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/fit/local_fields.h"
#include "weft/render/local_gamma.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;
using transmittance::MemoryRule;

constexpr MemoryRule kRules[] = {MemoryRule::segment, MemoryRule::renewal, MemoryRule::optical_depth,
                                 MemoryRule::carried};

std::string rule_key(MemoryRule r) { return fmt::format(R"(, "memory": "{}")", memory_rule_name(r)); }

using test::Estimate;
using test::image_mean;

// ---- a separable fine grid: C(i, j, k) = m(k / B) · U(i, j) ---------------------------------

constexpr int kB = 8;                                // coarse block edge (fine voxels)
constexpr int kCols = 16;                            // fine columns per edge: 2 × 2 coarse columns
constexpr double kH = 0.05;                          // fine voxel: slab 0.8 × 0.8 × 1.6
constexpr double kAlpha = 1.5;                       // U ~ Gamma(α, rate α): mean 1
const std::vector<double> kM{0.05, 0.05, 3.0, 1.0};  // block means along z: sparse, then dense
constexpr double kSigma = 1.0;

/// U at column (i, j): the B² quantiles of Gamma(α, α) at (q + ½)/B² over each coarse column's
/// B × B fine columns, so every coarse column holds the same empirical law.
double column_u(int i, int j) {
  static const boost::math::gamma_distribution<double> law(kAlpha, 1.0 / kAlpha);
  const int q = (i % kB) * kB + (j % kB);
  return boost::math::quantile(law, (q + 0.5) / (kB * kB));
}

volume::Grid separable_grid() {
  volume::Grid g(kH, "density");
  g.set_origin({0.0, 0.0, 0.0});
  for (int i = 0; i < kCols; ++i)
    for (int j = 0; j < kCols; ++j)
      for (int k = 0; k < kB * static_cast<int>(kM.size()); ++k)
        g.set_value(i, j, k, static_cast<float>(kM[static_cast<std::size_t>(k / kB)] * column_u(i, j)));
  return g;
}

/// The fine grid's exact transmittance along z averaged over its columns (what every pixel of a
/// camera looking along z averages), from the stored float values.
double fine_mean_transmittance(const volume::Grid& g) {
  double sum = 0.0;
  for (int i = 0; i < kCols; ++i)
    for (int j = 0; j < kCols; ++j) {
      double tau = 0.0;
      for (int k = 0; k < kB * static_cast<int>(kM.size()); ++k) tau += kSigma * kH * g.value(i, j, k);
      sum += std::exp(-tau);
    }
  return sum / (kCols * kCols);
}

/// A far pinhole on −z whose film covers the slab's face exactly (rays within 4e-4 rad of z).
std::string slab_scene(const fs::path& fields, const std::string& medium_extra, int spp) {
  const double d = 1000.0;
  const double fov = 2.0 * std::atan(0.4 / d) * 180.0 / M_PI;
  return fmt::format(R"({{
    "camera": {{"position": [0.4, 0.4, {}], "look_at": [0.4, 0.4, 0], "fov": {:.17g}, "width": 24, "height": 24}},
    "integrator": {{"spp": {}, "max_depth": 8, "rr_depth": 8, "seed": 9}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {{"type": "local-gamma", "fields": "{}", "sigma": {}{}}}}},
    "shapes": [{{"type": "box", "min": [0, 0, 0], "max": [0.8, 0.8, 1.6], "material": "boundary", "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                     -d, fov, spp, fields.string(), kSigma, medium_extra);
}

TEST(LocalGammaMemory, AlbedoZeroImageAgainstTheFineGridsTransmittance) {
  const volume::Grid g = separable_grid();
  const fs::path fields = fs::temp_directory_path() / "weft_lg_memory_separable.vdb";
  fit::save_local_fields(fit::local_fields(g, kB), fields, fit::FieldChannels::render);
  const double fine = fine_mean_transmittance(g);
  // The gamma shape's own error: the B² quantiles are a gamma law only up to quadrature (and
  // the fields' α is the quantiles' empirical one). Exact, from the same numbers the fields hold.
  double mean_u = 0.0, mean_u2 = 0.0;
  for (int i = 0; i < kB; ++i)
    for (int j = 0; j < kB; ++j) {
      mean_u += column_u(i, j) / (kB * kB);
      mean_u2 += column_u(i, j) * column_u(i, j) / (kB * kB);
    }
  const double alpha = mean_u * mean_u / (mean_u2 - mean_u * mean_u);
  double tau_bar = 0.0;
  for (const double m : kM) tau_bar += kSigma * m * mean_u * kB * kH;
  const double shape_error = std::abs(std::pow(1.0 + tau_bar / alpha, -alpha) - fine);
  ASSERT_LT(shape_error, 0.01);
  for (const MemoryRule r : kRules) {
    const RenderResult res = render(parse_scene(slab_scene(fields, R"(, "albedo": 0)" + rule_key(r), 64), "s", "."));
    const Estimate e = image_mean(res.image);
    const double tol = 5.0 * e.stderr_ + shape_error + 1e-4;
    SCOPED_TRACE(fmt::format("{}: image {:.5f} ± {:.5f}, fine {:.5f}, shape error {:.2g}", memory_rule_name(r), e.mean,
                             e.stderr_, fine, shape_error));
    RecordProperty(std::string(memory_rule_name(r)), fmt::format("{:.5f} +- {:.5f} (fine {:.5f}, shape error {:.2g})",
                                                                 e.mean, e.stderr_, fine, shape_error));
    EXPECT_GT(e.stderr_, 0.0);
    switch (r) {
      case MemoryRule::optical_depth:
      case MemoryRule::carried:
        EXPECT_NEAR(e.mean, fine, tol);  // exact on a separable medium (docs/render.md §5e)
        break;
      case MemoryRule::segment:
        EXPECT_GT(e.mean, fine + tol);  // the sparse blocks' distance lowers the dense blocks' hazard
        break;
      case MemoryRule::renewal:
        EXPECT_LT(e.mean, fine - tol);  // independent blocks: the correlation along the ray is lost
        break;
    }
  }
}

// ---- a varying field: furnace and seams ------------------------------------------------------

/// Coarse fields of n³ voxels of size h over [0, n·h)³, mean and variance varying voxel by voxel
/// (a third of the variances 0, a few voxels empty); with `split`, the same statistics in
/// voxels of half the size (each coarse voxel cut into 2³ equal ones).
fs::path varying_fields(const std::string& name, int n, double h, bool split) {
  const fs::path path = fs::temp_directory_path() / ("weft_lg_memory_" + name + ".vdb");
  const int f = split ? 2 : 1;
  std::vector<volume::Grid> grids;
  for (const std::string grid_name :
       {"mean_concentration", "var_concentration_x", "var_concentration_y", "var_concentration_z"}) {
    volume::Grid g(h / f, grid_name);
    g.set_origin({0.0, 0.0, 0.0});
    for (int k = 0; k < n * f; ++k)
      for (int j = 0; j < n * f; ++j)
        for (int i = 0; i < n * f; ++i) {
          Pcg32 rng = stream_for(17, static_cast<std::uint64_t>(((i / f) * n + j / f) * n + k / f));
          const double u = rng.uniform();
          const double mean = u < 0.1 ? 0.0 : 0.2 + 6.0 * u * u;
          const double v = rng.uniform();
          const double var = v < 0.33 ? 0.0 : mean * mean * (0.2 + 4.0 * v);
          if (mean > 0.0) g.set_value(i, j, k, static_cast<float>(grid_name == "mean_concentration" ? mean : var));
        }
    grids.push_back(g);
  }
  volume::save_grids(grids, path);
  return path;
}

TEST(LocalGammaMemory, VaryingFieldWhiteFurnaceRendersOne) {
  const fs::path fields = varying_fields("furnace", 4, 0.25, false);
  for (const MemoryRule r : kRules) {
    const std::string scene = fmt::format(R"({{
      "camera": {{"position": [1.7, 1.4, 2.9], "look_at": [0.5, 0.5, 0.5], "fov": 35, "width": 12, "height": 12}},
      "integrator": {{"spp": 48, "max_depth": 1000, "rr_depth": 1000, "seed": 4}},
      "materials": {{"boundary": {{"type": "null"}}}},
      "media": {{"m": {{"type": "local-gamma", "fields": "{}", "sigma": 3, "albedo": 1, "g": 0.3{}}}}},
      "shapes": [{{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "material": "boundary", "interior": "m"}}],
      "lights": [{{"type": "environment", "radiance": 1}}]
    }})",
                                          fields.string(), rule_key(r));
    const Estimate e = image_mean(render(parse_scene(scene, "furnace", ".")).image);
    EXPECT_GT(e.stderr_, 0.0) << memory_rule_name(r);  // NEE and phase sampling really mixed
    EXPECT_NEAR(e.mean, 1.0, 5.0 * e.stderr_) << memory_rule_name(r);
  }
}

TEST(LocalGammaMemory, SeamsBetweenEqualCellsChangeNothingExceptUnderRenewal) {
  const fs::path whole = varying_fields("whole", 4, 0.25, false);
  const fs::path halves = varying_fields("halves", 4, 0.25, true);
  for (const MemoryRule r : kRules) {
    LocalGammaField a(whole, 2.0, r);
    LocalGammaField b(halves, 2.0, r);
    Pcg32 rng = stream_for(3, 0);
    double worst = 0.0;
    for (int i = 0; i < 200; ++i) {
      // Rays from a point inside the fields in a random direction, through several voxels.
      const volume::Ray ray{{0.05 + 0.9 * rng.uniform(), 0.05 + 0.9 * rng.uniform(), 0.05 + 0.9 * rng.uniform()},
                            {0.0, 0.0, 0.0}};
      const double z = 2.0 * rng.uniform() - 1.0;
      const double phi = 2.0 * M_PI * rng.uniform();
      const double s = std::sqrt(1.0 - z * z);
      volume::Ray dir = ray;
      dir.direction = {s * std::cos(phi), s * std::sin(phi), z};
      for (const auto o : {transmittance::Origin::source, transmittance::Origin::scatterer}) {
        const double la = a.log_transmittance(dir, 0.0, 1.8, o);
        const double lb = b.log_transmittance(dir, 0.0, 1.8, o);
        worst = std::max(worst, std::abs(la - lb) / (1.0 + std::abs(la)));
      }
    }
    if (r == MemoryRule::renewal) {
      EXPECT_GT(worst, 1e-2);  // every face restarts the memory: the cut is an interface
    } else {
      EXPECT_LT(worst, 1e-6) << memory_rule_name(r);  // float grids: the statistics are equal to 1e-7
    }
  }
}

// The rule is a key of the scene medium: it round-trips, and a misspelt one is a one-line error
// naming the medium and the known rules.
TEST(LocalGammaMemory, RuleIsASceneKeyThatRoundTrips) {
  const fs::path fields = varying_fields("keys", 2, 0.5, false);
  for (const MemoryRule r : kRules) {
    const SceneDesc s = parse_scene(slab_scene(fields, rule_key(r), 1), "s", ".");
    EXPECT_EQ(s.media.at("m").memory, r);
    EXPECT_EQ(parse_scene(scene_to_json(s), "again", ".").media.at("m").memory, r);
  }
  EXPECT_THAT([&] { (void)parse_scene(slab_scene(fields, R"(, "memory": "optical_depth")", 1), "s", "."); },
              weft::test::throws_one_line_error_with({"optical-depth", "media.m"}));
}

}  // namespace
}  // namespace weft::render
