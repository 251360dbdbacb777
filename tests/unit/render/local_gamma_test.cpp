#include "weft/render/local_gamma.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/majorants.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;

/// Writes the grids `weft fit --block` writes, 1-unit coarse voxels (indices [0,4)×[0,4)×[0,nz)),
/// with mean C(k) and variance V(k) per z layer (every axis gets the same V).
fs::path write_fields(const std::string& name, const std::vector<double>& mean, const std::vector<double>& var) {
  const fs::path path = fs::temp_directory_path() / ("weft_local_gamma_" + name + ".vdb");
  std::vector<volume::Grid> grids;
  volume::Grid m(1.0, "mean_concentration");
  for (int k = 0; k < static_cast<int>(mean.size()); ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) m.set_value(i, j, k, static_cast<float>(mean[static_cast<std::size_t>(k)]));
  grids.push_back(m);
  for (const char axis : std::string("xyz")) {
    volume::Grid v(1.0, std::string("var_concentration_") + axis);
    for (int k = 0; k < static_cast<int>(var.size()); ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) v.set_value(i, j, k, static_cast<float>(var[static_cast<std::size_t>(k)]));
    grids.push_back(v);
  }
  volume::save_grids(grids, path);
  return path;
}

// OpenVDB voxel k is centred on k, so layer k spans z ∈ [k − ½, k + ½): t = 0 at the bottom face.
const volume::Ray kRayZ{{2.0, 2.0, -0.5}, {0.0, 0.0, 1.0}};

// A constant field is the homogeneous gamma law T = (1 + σt/β)^−α, α = C̄²/V, β = C̄/V.
TEST(LocalGamma, ConstantFieldIsHomogeneousGammaLaw) {
  const double c = 2.0, v = 0.5, sigma = 1.5;
  LocalGammaField f(write_fields("const", std::vector<double>(8, c), std::vector<double>(8, v)), sigma);
  const double alpha = c * c / v, beta = c / v;
  for (const double t : {0.1, 0.5, 1.0, 2.5, 3.0, 7.9}) {
    const double expected = -alpha * std::log1p(sigma * t / beta);
    EXPECT_NEAR(f.log_transmittance(kRayZ, 0.0, t), expected, 1e-9 * (1.0 + std::abs(expected))) << t;
  }
  // The memory starts at the segment start: a segment starting at 3 sees the same law.
  EXPECT_NEAR(f.log_transmittance(kRayZ, 3.0, 5.0), -alpha * std::log1p(sigma * 2.0 / beta), 1e-9);
}

// V = 0 blocks are exponential with μ = σC̄.
TEST(LocalGamma, ZeroVarianceIsExponential) {
  LocalGammaField f(write_fields("exp", std::vector<double>(4, 3.0), std::vector<double>(4, 0.0)), 0.5);
  EXPECT_NEAR(f.log_transmittance(kRayZ, 0.0, 3.5), -0.5 * 3.0 * 3.5, 1e-12);
}

// Inverting H: sampled distances follow CDF 1 − e^{−H(t)}, with H integrated numerically
// from the hazard σC̄(z)/(1 + κ(z)s) over a field that changes every layer.
TEST(LocalGamma, SamplingMatchesAccumulatedHazardCdf) {
  const std::vector<double> mean{0.5, 2.0, 0.0, 1.0, 3.0, 0.2};
  const std::vector<double> var{0.1, 4.0, 0.0, 0.0, 0.5, 1e-3};
  const double sigma = 0.8;
  // The hazard below is the `segment` rule's (memory = distance from the segment start), named
  // because the medium's default is optical-depth (docs/render.md §5e, tested in
  // local_gamma_memory_test.cpp).
  LocalGammaField f(write_fields("layers", mean, var), sigma, transmittance::MemoryRule::segment);
  // Midpoint rule per layer (the hazard jumps at layer faces, so each layer is integrated alone).
  auto numeric_h = [&](double t) {
    double h = 0.0;
    for (std::size_t k = 0; k < mean.size() && static_cast<double>(k) < t; ++k) {
      if (mean[k] <= 0.0) continue;
      const double a = static_cast<double>(k);
      const double b = std::min(t, a + 1.0);
      const int m = 20000;
      const double dt = (b - a) / m;
      for (int i = 0; i < m; ++i) {
        const double s = a + (i + 0.5) * dt;
        h += sigma * mean[k] / (1.0 + sigma * var[k] / mean[k] * s) * dt;
      }
    }
    return h;
  };
  const int n = 40000;
  std::vector<double> ts;
  Pcg32 rng = stream_for(7, 0);
  for (int i = 0; i < n; ++i) ts.push_back(f.sample_distance(kRayZ, 0.0, 6.0, -std::log(rng.uniform_open())));
  for (const double t : {0.3, 1.0, 1.7, 2.5, 3.4, 4.6, 5.9}) {
    const double p = -std::expm1(-numeric_h(t));
    EXPECT_NEAR(-std::expm1(f.log_transmittance(kRayZ, 0.0, t)), p, 1e-6) << t;
    double hits = 0;
    for (const double s : ts) hits += s <= t ? 1 : 0;
    const double se = std::sqrt(p * (1 - p) / n);
    EXPECT_NEAR(hits / n, p, 5 * se + 1e-12) << "t=" << t;
  }
}

// A shadow's transmittance is e^{−H} exactly while it stays above ShadowRoulette::kBelow and an
// unbiased estimate of it below (the walk ended early by Russian roulette): mean within 5σ.
TEST(LocalGamma, ShadowTransmittanceIsExactWhileLargeAndUnbiasedBelow) {
  LocalGammaField f(write_fields("roulette", {0.5, 2.0, 0.2, 3.0}, {0.1, 1.5, 0.05, 2.0}), 3.0);
  Pcg32 rng = stream_for(5, 0);
  for (const auto origin : {transmittance::Origin::source, transmittance::Origin::scatterer}) {
    for (const double t : {0.3, 1.5, 2.5, 4.0}) {
      const double exact = std::exp(f.log_transmittance(kRayZ, 0.0, t, origin));
      if (exact > volume::ShadowRoulette::kBelow) {
        EXPECT_NEAR(f.transmittance(kRayZ, 0.0, t, origin, rng), exact, 1e-12 * exact) << t;
        continue;
      }
      constexpr int kN = 40000;
      double sum = 0.0;
      double sum2 = 0.0;
      for (int i = 0; i < kN; ++i) {
        const double tr = f.transmittance(kRayZ, 0.0, t, origin, rng);
        sum += tr;
        sum2 += tr * tr;
      }
      const double mean = sum / kN;
      const double se = std::sqrt(std::max(0.0, sum2 / kN - mean * mean) / kN);
      EXPECT_GT(se, 0.0) << t;  // the roulette ran
      EXPECT_NEAR(mean, exact, 5.0 * se) << t;
    }
  }
}

TEST(LocalGamma, MissingFileAndBadSigmaAreOneLineErrors) {
  EXPECT_THAT([] { const LocalGammaField f("/nonexistent/fields.vdb", 1.0); },
              weft::test::throws_one_line_error_with({"/nonexistent/fields.vdb"}));
  const fs::path ok = write_fields("sigma", {1.0}, {0.1});
  EXPECT_THROW(LocalGammaField(ok, -1.0), Error);
  EXPECT_THROW(LocalGammaField(ok, std::nan("")), Error);
}

}  // namespace
}  // namespace weft::render
