// The local-gamma field held as dense records and walked by volume::DenseWalk gives the tree
// walk's numbers bit for bit (docs/render.md §5b "Dense walk").
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "weft/core/rng.h"
#include "weft/render/local_gamma.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;

/// Writes a field of voxels of 0.37 at an odd origin over the voxels [lo, hi) where
/// matter(i, j, k, rng) holds: a random mean and a different random variance per axis (some 0:
/// exponential voxels); the rest vacuum.
template <typename Matter>
fs::path write_fields(const std::string& file, Pcg32 rng, const std::array<int, 3>& lo, const std::array<int, 3>& hi,
                      Matter&& matter) {
  fs::path path = fs::temp_directory_path() / file;
  volume::Grid mean(0.37, "mean_concentration");
  std::vector<volume::Grid> var;
  for (const char axis : std::string("xyz")) var.emplace_back(0.37, std::string("var_concentration_") + axis);
  for (auto* g : {&mean, &var[0], &var[1], &var[2]}) g->set_origin({-1.3, 0.2, 0.9});
  for (int i = lo[0]; i < hi[0]; ++i)
    for (int j = lo[1]; j < hi[1]; ++j)
      for (int k = lo[2]; k < hi[2]; ++k) {
        if (!matter(i, j, k, rng)) continue;
        const double c = 0.02 + 0.6 * rng.uniform();
        mean.set_value(i, j, k, static_cast<float>(c));
        for (auto& v : var)
          if (rng.uniform() < 0.85) v.set_value(i, j, k, static_cast<float>(c * c * 2.0 * rng.uniform()));
      }
  std::vector<volume::Grid> grids{mean};
  grids.insert(grids.end(), var.begin(), var.end());
  volume::save_grids(grids, path);
  return path;
}

/// A hand-built field over a box that crosses leaf boundaries and negative indices: a third of
/// the voxels vacuum, some isolated inside the box.
fs::path write_random_fields() {
  return write_fields("weft_local_gamma_dense.vdb", Pcg32(17, 4), {-9, -3, -5}, {7, 11, 4},
                      [](int, int, int, Pcg32& rng) { return !(rng.uniform() < 0.33); });
}

/// A field of long vacuum runs over a box of 40×36×12 voxels: a few yarn-like lines of matter
/// and scattered voxels, the rest empty (whole leaves of it), so the tree walk crosses most of
/// the box a node at a time.
fs::path write_sparse_fields() {
  return write_fields("weft_local_gamma_dense_sparse.vdb", Pcg32(23, 6), {-20, -10, -6}, {20, 26, 6},
                      [](int i, int j, int k, Pcg32& rng) {
                        const bool yarn = (j == 3 && k == -2) || (i == 9 && k == 4) || (i == -15 && j == 20);
                        // The box reaches both far corners.
                        const bool corners = (i == -20 && j == -10 && k == -6) || (i == 19 && j == 25 && k == 5);
                        return yarn || corners || rng.uniform() < 0.002;
                      });
}

volume::Ray random_ray(Pcg32& rng, bool on_face) {
  volume::Ray ray;
  ray.origin = {-6.0 + 8.0 * rng.uniform(), -4.0 + 10.0 * rng.uniform(), -5.0 + 8.0 * rng.uniform()};
  if (on_face) {
    // Along an axis on a voxel face: the half-open convention must hold in both walks.
    const auto a = static_cast<std::size_t>(rng.uniform() * 3.0) % 3;
    ray.direction = {0.0, 0.0, 0.0};
    ray.direction[a] = rng.uniform() < 0.5 ? -1.0 : 1.0;
    const std::size_t b = (a + 1) % 3;
    const double origin_b = b == 0 ? -1.3 : (b == 1 ? 0.2 : 0.9);
    ray.origin[b] = origin_b + 0.37 * std::round((ray.origin[b] - origin_b) / 0.37);
    return ray;
  }
  const double z = 1.0 - 2.0 * rng.uniform();
  const double phi = 2.0 * std::numbers::pi * rng.uniform();
  ray.direction = {std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z};
  return ray;
}

/// The dense walk and the tree walk of the field at `path` give the same log T, sampled
/// distances and roulette shadows (with their random draws) bit for bit, under every memory
/// rule, from a source and from a scatterer; returns how many segments met matter.
int expect_walks_equal(const fs::path& path, int rays, double reach) {
  int crossed = 0;
  for (const auto rule : transmittance::kMemoryRules) {
    LocalGammaField dense(path, 2.7, rule);
    LocalGammaField tree(path, 2.7, rule, 0);
    EXPECT_TRUE(dense.dense());
    EXPECT_FALSE(tree.dense());
    const auto dense_clone = dense.clone();
    EXPECT_TRUE(dense_clone->dense());
    Pcg32 rng(3, static_cast<std::uint64_t>(rule));
    for (int n = 0; n < rays; ++n) {
      const volume::Ray ray = random_ray(rng, n % 4 == 0);
      const double t0 = 0.5 * rng.uniform();
      const double t1 = t0 + reach * rng.uniform();
      for (const auto origin : {transmittance::Origin::source, transmittance::Origin::scatterer}) {
        const double h = tree.log_transmittance(ray, t0, t1, origin);
        EXPECT_EQ(dense.log_transmittance(ray, t0, t1, origin), h) << n;
        EXPECT_EQ(dense_clone->log_transmittance(ray, t0, t1, origin), h) << n;
        if (h < 0.0) ++crossed;
        const double target = -std::log(rng.uniform_open());
        EXPECT_EQ(dense.sample_distance(ray, t0, t1, target, origin), tree.sample_distance(ray, t0, t1, target, origin))
            << n;
        // Shadows: the same roulette draws on the same stream.
        Pcg32 a = stream_for(11, static_cast<std::uint64_t>(n));
        Pcg32 b = a;
        EXPECT_EQ(dense.transmittance(ray, t0, t1, origin, a), tree.transmittance(ray, t0, t1, origin, b)) << n;
        EXPECT_EQ(a.uniform(), b.uniform()) << n;
      }
    }
  }
  return crossed;
}

TEST(LocalGammaDense, DenseRecordsWalkEqualsTheTreeWalkBitForBit) {
  // Many of the 800 segments per rule met the field.
  EXPECT_GT(expect_walks_equal(write_random_fields(), 400, 12.0), 4 * 100);
}

// Long vacuum runs, crossed voxel by voxel by the dense walk and a node at a time by the tree
// walk: the same numbers.
TEST(LocalGammaDense, LongVacuumRunsGiveTheTreeWalksBits) {
  EXPECT_GT(expect_walks_equal(write_sparse_fields(), 1500, 30.0), 4 * 100);
}

// A box larger than the records' budget keeps the trees.
TEST(LocalGammaDense, ABoxOverTheBudgetKeepsTheTrees) {
  const fs::path path = write_random_fields();
  EXPECT_FALSE(LocalGammaField(path, 1.0, transmittance::kDefaultMemoryRule, 1024).dense());
  EXPECT_TRUE(LocalGammaField(path, 1.0, transmittance::kDefaultMemoryRule, std::uint64_t{1} << 20).dense());
}

}  // namespace
}  // namespace weft::render
