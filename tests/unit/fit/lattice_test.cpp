// Predictions do not depend on where the grid's index lattice starts (docs/validate.md "Blocks
// anchored to the cloth"): the same voxels at index origins shifted by 0…L−1 voxels on each axis
// (and by negative amounts) give the same predictions of every model, on every beam.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include <fmt/core.h>

#include "weft/fit/models.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"

namespace weft::fit {
namespace {

using volume::Grid;

// A structured, anisotropic field with empty margins and partial blocks (extents 23 × 19 × 14
// are not multiples of L = 5): yarn-like bands along x and y, a hash for fibre-scale noise.
float cloth_value(int i, int j, int k) {
  const std::uint32_t hsh = static_cast<std::uint32_t>(i * 73856093) ^ static_cast<std::uint32_t>(j * 19349663) ^
                            static_cast<std::uint32_t>(k * 83492791);
  const double noise = static_cast<double>(hsh % 1000u) / 1000.0;
  const bool warp = (j / 4) % 2 == 0 && k >= 3 && k < 8;
  const bool weft = (i / 6) % 2 == 1 && k >= 6 && k < 11;
  if (!warp && !weft) return noise < 0.05 ? 0.1f : 0.0f;  // flyaway hairs
  return static_cast<float>(0.2 + 0.6 * noise);
}

Grid shifted_cloth(const std::array<int, 3>& shift) {
  Grid g(0.02);
  g.set_origin({0.0, 0.0, 0.0});
  for (int i = 0; i < 23; ++i) {
    for (int j = 0; j < 19; ++j) {
      for (int k = 0; k < 14; ++k) {
        const float v = cloth_value(i, j, k);
        if (v > 0.0f) g.set_value(i + shift[0], j + shift[1], k + shift[2], v);
      }
    }
  }
  return g;
}

std::vector<PredictedModel> predict(const Grid& g, const std::array<double, 3>& d) {
  volume::BeamSpec b;
  b.direction = d;
  PredictionSpec spec;
  spec.direction = d;
  spec.sigma = 40.0;
  spec.scale = 0.1;  // L = 5 voxels
  return predict_axis(g, spec, volume::beam_depths(g, b));
}

TEST(Lattice, EveryModelIsTheSameAtEveryIndexOrigin) {
  const Grid base = shifted_cloth({0, 0, 0});
  const std::array<std::array<double, 3>, 6> dirs{
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}};
  std::vector<std::vector<PredictedModel>> reference;
  for (const auto& d : dirs) reference.push_back(predict(base, d));
  // Shifts 1…L−1 along each axis alone, all three at once, and negative and large offsets
  // (as Grid.from_numpy's index_origin or another tool's lattice would give).
  std::vector<std::array<int, 3>> shifts;
  for (int a = 0; a < 3; ++a) {
    for (int s = 1; s < 5; ++s) {
      std::array<int, 3> v{0, 0, 0};
      v[static_cast<std::size_t>(a)] = s;
      shifts.push_back(v);
    }
  }
  shifts.push_back({3, 2, 1});
  shifts.push_back({-7, -3, -1});
  shifts.push_back({1001, -513, 37});
  double worst = 0.0;
  for (const auto& shift : shifts) {
    const Grid g = shifted_cloth(shift);
    for (std::size_t di = 0; di < dirs.size(); ++di) {
      const auto models = predict(g, dirs[di]);
      ASSERT_EQ(models.size(), reference[di].size());
      for (std::size_t m = 0; m < models.size(); ++m) {
        const auto& a = models[m].log_t;
        const auto& b = reference[di][m].log_t;
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t k = 0; k < a.size(); ++k) {
          // Equal up to the order in which face patches are summed (they move with the lattice).
          const double diff = std::abs(a[k] - b[k]);
          worst = std::max(worst, diff);
          EXPECT_LE(diff, 1e-12 * (1.0 + std::abs(b[k]))) << models[m].name << " shift " << shift[0] << "," << shift[1]
                                                          << "," << shift[2] << " dir " << di << " k " << k;
        }
      }
    }
  }
  RecordProperty("worst_abs_log_t_difference", fmt::format("{:.3g}", worst));
}

TEST(Lattice, TheLocalModelsSeeTheStructure) {
  // Guard against a vacuous pass: the local models differ from the one-law models on this field.
  const auto models = predict(shifted_cloth({0, 0, 0}), {0, 0, 1});
  const auto& gamma = models[0].log_t;
  bool differs = false;
  for (const auto& m : models) {
    if (m.name.rfind("local-gamma", 0) != 0) continue;
    for (std::size_t k = 0; k < gamma.size(); ++k) differs = differs || std::abs(m.log_t[k] - gamma[k]) > 1e-3;
  }
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace weft::fit
