// Generators of explicit 2D media (S.11.1): particle counts, periodicity, lattice geometry and the
// statistics of perturbation and random-walk steps.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "data_gen/media2d/medium.h"
#include "data_gen/media2d/simulation.h"
#include "weft/core/error.h"

namespace weft::media2d {
namespace {

// Kolmogorov–Smirnov statistic √n·D of `xs` against the exponential law of mean `mean`.
double ks_exponential(std::vector<double> xs, double mean) {
  std::sort(xs.begin(), xs.end());
  const double n = static_cast<double>(xs.size());
  double d = 0.0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const double cdf = -std::expm1(-xs[i] / mean);
    d = std::max({d, std::abs(cdf - static_cast<double>(i) / n), std::abs(static_cast<double>(i + 1) / n - cdf)});
  }
  return std::sqrt(n) * d;
}
// √n·D above this has probability < 1e-6 under the null (asymptotic Kolmogorov law).
const double kKsCritical = std::sqrt(-0.5 * std::log(0.5e-6));

TEST(Santalo, ParticleCountInvertsMeanFreePath) {
  for (const double r : {1e-5, 1e-4, 3e-4}) {
    for (const double lambda : {0.01, 0.025, 0.1}) {
      const std::size_t n = particle_count(r, lambda);
      // Rounding n to an integer moves λ by at most λ/(2n) relative to the exact solution.
      EXPECT_NEAR(santalo_mean_free_path(n, r), lambda, lambda / static_cast<double>(n)) << r << " " << lambda;
    }
  }
  // λ = (1 − nπr²)/(2nr) at a hand-checked point: n = 1000, r = 1e-3 → (1 − π·1e-3)/2.
  EXPECT_NEAR(santalo_mean_free_path(1000, 1e-3), (1.0 - std::numbers::pi * 1e-3) / 2.0, 1e-15);
}

struct BadSpec {
  const char* what;
  MediumSpec spec;
  const char* message;
};

TEST(Medium, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<BadSpec> table{
      {"eta = 1", {1.0, 1e-4, 0.025, 1000, 0.0}, "eta"},
      {"eta > 1", {1.5, 1e-4, 0.025, 1000, 0.0}, "eta"},
      {"eta < -1", {-1.01, 1e-4, 0.025, 1000, 0.0}, "eta"},
      {"eta NaN", {nan, 1e-4, 0.025, 1000, 0.0}, "eta"},
      {"r = 0", {0.0, 0.0, 0.025, 1000, 0.0}, "radius"},
      {"r < 0", {0.0, -1e-4, 0.025, 1000, 0.0}, "radius"},
      {"lambda = 0", {0.0, 1e-4, 0.0, 1000, 0.0}, "mean free path"},
      {"dense packing", {0.0, 1e-3, 0.01, 1000, 0.0}, "packing fraction"},
      {"too few particles", {0.0, 1e-2, 10.0, 1000, 0.0}, "at least"},
      {"cluster size 0", {0.5, 1e-4, 0.025, 0, 0.0}, "cluster size"},
      {"negative step unit", {0.5, 1e-4, 0.025, 10, -1.0}, "step unit"},
      // Positions after a step this long round by more than r/1000: the medium collapsed.
      {"step unit past the positions' resolution", {0.5, 1e-4, 0.025, 10, 1e20}, "rounds it by more than"},
      {"step unit just past it", {0.5, 1e-4, 0.025, 10, 1.01 * max_step_unit(1e-4)}, "step unit"},
  };
  for (const auto& row : table) {
    EXPECT_THAT([&] { validate(row.spec); }, ::testing::ThrowsMessage<Error>(::testing::HasSubstr(row.message)))
        << row.what;
  }
  EXPECT_NO_THROW(validate(MediumSpec{-1.0, 1e-4, 0.025, 1000, 0.0}));
  EXPECT_NO_THROW(validate(MediumSpec{0.5, 1e-4, 0.025, 10, max_step_unit(1e-4)}));
}

TEST(Lattice, SitesArePeriodicDistinctAndHexagonal) {
  const MediumSpec spec{-1.0, 1e-4, 0.025, 1000, 0.0};
  const LatticeLayout layout = lattice_layout(spec);
  ASSERT_EQ(layout.ny % 2, 0U);
  ASSERT_EQ(layout.rise_steps % 2, 0U);
  EXPECT_GE(layout.rise, 2.0 * spec.radius);
  const std::vector<Point2> sites = lattice_sites(layout);
  ASSERT_EQ(sites.size(), layout.count());
  for (const auto& p : sites) {
    ASSERT_GE(p.x, 0.0);
    ASSERT_LT(p.x, 1.0);
    ASSERT_GE(p.y, 0.0);
    ASSERT_LT(p.y, 1.0);
  }
  // Row j continued past its last column lands on the first site of row j + k: the seam closes.
  const double nx = static_cast<double>(layout.nx);
  for (std::size_t j = 0; j < layout.ny; j += 7) {
    const Point2 last = sites[j * layout.nx + layout.nx - 1];
    const Point2 next{last.x + 1.0 / nx, last.y + layout.rise};
    const Point2 first = sites[((j + layout.rise_steps) % layout.ny) * layout.nx];
    const Point2 d = periodic_delta(next, first);
    EXPECT_LT(std::hypot(d.x, d.y), 1e-12) << "row " << j;
  }
  // Hexagonal: the six nearest neighbours of a site are nearly equidistant. The shear (rise per
  // column, one shadow width) changes them by about rise·nx ≈ √(2r/λ) (2.8 % at the default
  // r = 1e-5, λ = 0.025), rounding nx, ny to integers by about 1/nx.
  const LatticeLayout fine = lattice_layout(MediumSpec{-1.0, 1e-5, 0.025, 1000, 0.0});
  const std::vector<Point2> fine_sites = lattice_sites(fine);
  const Point2 c = fine_sites[(fine.ny / 2) * fine.nx + fine.nx / 2];
  std::vector<double> dist;
  for (const auto& p : fine_sites) {
    const Point2 d = periodic_delta(c, p);
    const double l = std::hypot(d.x, d.y);
    if (l > 0.0 && l < 1e-2) dist.push_back(l);
  }
  ASSERT_GT(dist.size(), 7U);
  std::partial_sort(dist.begin(), dist.begin() + 7, dist.end());
  const double shear = fine.rise * static_cast<double>(fine.nx);
  EXPECT_LT(shear, 0.03);
  EXPECT_LT(dist[5] / dist[0], 1.0 + 2.0 * shear + 2.0 / static_cast<double>(fine.nx));
  EXPECT_GT(dist[6] / dist[5], 1.5);  // the next shell is at √3 times the first
}

TEST(Lattice, NoParticleMasksAnotherAlongPropagation) {
  const MediumSpec spec{-1.0, 1e-4, 0.025, 1000, 0.0};
  const LatticeLayout layout = lattice_layout(spec);
  const std::vector<Point2> sites = lattice_sites(layout);
  // Along +x, consecutive sites of a row are one shadow (2r) or more apart across the ray, so no
  // particle hides behind its row neighbour.
  for (std::size_t j = 0; j < layout.ny; j += 11) {
    for (std::size_t i = 0; i + 1 < layout.nx; ++i) {
      const Point2 d = periodic_delta(sites[j * layout.nx + i], sites[j * layout.nx + i + 1]);
      ASSERT_GE(std::abs(d.y), 2.0 * spec.radius * (1.0 - 1e-9)) << j << " " << i;
    }
  }
  // Hence no corridor: every ray along +x hits a particle within two row crossings (1/k each) plus
  // a column's jitter, and none survives — the lattice's deterministic behaviour (η = −1).
  Pcg32 gen(3);
  const Medium lattice = generate(spec, gen);
  EXPECT_EQ(lattice.perturbed, 0U);
  Pcg32 rays(4);
  const std::vector<double> paths = source_free_paths(lattice, spec.mean_free_path, 0.0, 4000, 40.0, rays);
  const double horizon =
      (2.0 / static_cast<double>(layout.rise_steps) + 1.0 / static_cast<double>(layout.nx)) / spec.mean_free_path;
  double mean = 0.0;
  for (const double f : paths) {
    ASSERT_LE(f, horizon);
    mean += f;
  }
  mean /= static_cast<double>(paths.size());
  // Free paths are (nearly) uniform on [0, 1/k]: the linear law (S.58) with mean 1/(2k).
  const double expected = 0.5 / static_cast<double>(layout.rise_steps) / spec.mean_free_path;
  const double se = expected / std::sqrt(3.0 * static_cast<double>(paths.size()));
  const double jitter = 1.0 / static_cast<double>(layout.nx) / spec.mean_free_path;
  EXPECT_NEAR(mean, expected, 5.0 * se + jitter);
}

TEST(Perturbation, LengthsFollowExponentialLawAndProbability) {
  const MediumSpec spec{-0.6, 1e-4, 0.025, 1000, 0.0};
  const LatticeLayout layout = lattice_layout(spec);
  const std::vector<Point2> sites = lattice_sites(layout);
  Pcg32 rng(11);
  const Medium m = generate(spec, rng);
  ASSERT_EQ(m.centers.size(), sites.size());
  std::vector<double> lengths;
  for (std::size_t i = 0; i < sites.size(); ++i) {
    const Point2 d = periodic_delta(sites[i], m.centers[i]);
    const double l = std::hypot(d.x, d.y);
    if (l > 0.0) lengths.push_back(l);
  }
  EXPECT_EQ(lengths.size(), m.perturbed);
  // Perturbed with probability 1 − |η|: binomial, 5σ.
  const double n = static_cast<double>(sites.size());
  const double p = 0.4;
  EXPECT_NEAR(static_cast<double>(lengths.size()) / n, p, 5.0 * std::sqrt(p * (1.0 - p) / n));
  // s = −log(ξ)(1 − |η|)² ℓ_step (S.11.1).
  const double mean = 0.4 * 0.4 * step_unit(spec);
  EXPECT_LT(ks_exponential(lengths, mean), kKsCritical);
  // A wrong mean by 5 % is detected by the same statistic (the test has power).
  EXPECT_GT(ks_exponential(lengths, 1.05 * mean), kKsCritical);
}

TEST(RandomWalk, StepsFollowExponentialLawAndWrap) {
  const MediumSpec spec{0.5, 1e-4, 0.025, 500, 0.0};
  Pcg32 rng(12);
  const Medium m = generate(spec, rng);
  ASSERT_EQ(m.centers.size(), particle_count(spec.radius, spec.mean_free_path));
  ASSERT_EQ(m.cluster_size, 500U);
  std::vector<double> steps;
  for (std::size_t i = 0; i < m.centers.size(); ++i) {
    const Point2 c = m.centers[i];
    ASSERT_TRUE(c.x >= 0.0 && c.x < 1.0 && c.y >= 0.0 && c.y < 1.0) << i;
    if (i % m.cluster_size == 0) continue;
    const Point2 d = periodic_delta(m.centers[i - 1], c);
    steps.push_back(std::hypot(d.x, d.y));
  }
  const double mean = 0.25 * step_unit(spec);
  EXPECT_LT(ks_exponential(steps, mean), kKsCritical);
  EXPECT_GT(ks_exponential(steps, 1.02 * mean), kKsCritical);
}

TEST(RandomWalk, LargeStepsWrapAroundTheSquare) {
  // ℓ_step = 1 makes steps of about a domain length: positions must still land in [0, 1).
  const MediumSpec spec{0.1, 1e-4, 0.025, 100, 1.0};
  Pcg32 rng(13);
  const Medium m = generate(spec, rng);
  std::size_t crossed = 0;
  for (std::size_t i = 1; i < m.centers.size(); ++i) {
    const Point2 c = m.centers[i];
    ASSERT_TRUE(c.x >= 0.0 && c.x < 1.0 && c.y >= 0.0 && c.y < 1.0) << i;
    if (std::abs(c.x - m.centers[i - 1].x) > 0.5) ++crossed;
  }
  EXPECT_GT(crossed, m.centers.size() / 10);
}

TEST(Poisson, PositionsAreUniform) {
  const MediumSpec spec{0.0, 1e-4, 0.025, 1000, 0.0};
  Pcg32 rng(14);
  const Medium m = generate(spec, rng);
  // χ² over a 10 × 10 grid of cells (99 dof): mean 99, sd 14; 99 + 5·14 as a bound.
  std::vector<double> counts(100, 0.0);
  for (const auto& c : m.centers)
    counts[static_cast<std::size_t>(c.y * 10) * 10 + static_cast<std::size_t>(c.x * 10)]++;
  const double expected = static_cast<double>(m.centers.size()) / 100.0;
  double chi2 = 0.0;
  for (const double c : counts) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, 99.0 + 5.0 * std::sqrt(2.0 * 99.0));
}

}  // namespace
}  // namespace weft::media2d
