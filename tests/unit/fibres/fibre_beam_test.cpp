// T_fibre against closed forms (docs/validate.md §Fibre ground truth): a single straight fibre
// (its shadow's area fraction; with internal extinction, the chord integral), a regular array of
// parallel fibres, random isotropic fibres against the Boolean-model law, and thread-count
// independence. Statistical checks use jittered rays and tolerances of 4 standard errors.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/fibres/fibre_beam.h"

namespace weft::fibres {
namespace {

const volume::WorldBox kUnitBox{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};

volume::BeamSpec beam(std::array<double, 3> d, int rays, std::uint64_t seed = 1) {
  volume::BeamSpec s;
  s.direction = d;
  s.rays_per_column = rays;
  s.jitter = rays > 1;
  s.seed = seed;
  return s;
}

std::size_t depth_index(const volume::TransmittanceCurve& c, double t) {
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (std::abs(c.depth[k] - t) < 1e-9) return k;
  }
  ADD_FAILURE() << "no depth " << t;
  return 0;
}

/// A fibre along x through (y0, z0) that spans the box in x (its caps outside).
FibreSet straight_fibre(double y0, double z0, double r) {
  FibreSet f;
  f.add({{-0.5, y0, z0}, {1.5, y0, z0}}, r);
  return f;
}

/// (1/W)∫ exp(−κ·ℓ(y, t)) dy over the fibre's width, ℓ = the chord of the ray at offset y cut
/// at depth t: clamp(t − (z0 − c), 0, 2c), c = √(r² − y²); plus the unshadowed 1 − 2r/W.
double chord_integral(double kappa, double r, double z0, double t, double width) {
  constexpr int n = 4000;  // Simpson in y = r·sin θ: a smooth integrand, exact to ~1e−13
  double acc = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double th = -std::numbers::pi / 2 + std::numbers::pi * i / n;
    const double c = r * std::cos(th);
    const double len = std::clamp(t - (z0 - c), 0.0, 2.0 * c);
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    acc += w * r * std::cos(th) * std::exp(-kappa * len);
  }
  acc *= std::numbers::pi / n / 3.0;
  return 1.0 - 2.0 * r / width + acc / width;
}

TEST(FibreBeam, SingleOpaqueFibreOnCellCentresBlocksItsShadowExactly) {
  const CapsuleIndex index(straight_fibre(0.5, 0.5, 0.05));
  const auto c = measure_fibre_beam(index, kUnitBox, 0.01, beam({0, 0, 1}, 1));
  ASSERT_EQ(c.rays, 10000U);
  // Rays at y = (j + ½)/100 with |y − ½| < r: j = 45..54, 10 of 100 rows.
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (c.depth[k] < 0.449) {
      EXPECT_EQ(c.transmittance(k), 1.0) << c.depth[k];
    }
    if (c.depth[k] > 0.551) {
      EXPECT_NEAR(c.transmittance(k), 0.9, 1e-12) << c.depth[k];
    }
  }
}

TEST(FibreBeam, SingleOpaqueFibreJitteredMatchesShadowFraction) {
  const double r = 0.037;
  const CapsuleIndex index(straight_fibre(0.43, 0.5, r));
  for (const auto& d : {std::array<double, 3>{0, 0, 1}, std::array<double, 3>{0, 0, -1}}) {
    const auto c = measure_fibre_beam(index, kUnitBox, 0.02, beam(d, 16, 3));
    const std::size_t k = c.size() - 1;
    EXPECT_NEAR(c.transmittance(k), 1.0 - 2.0 * r, 4.0 * c.stderr_abs(k));
    EXPECT_GT(c.stderr_abs(k), 0.0);
  }
  // Along the fibre's own axis: the rays inside its disc are blocked from the start.
  const auto c = measure_fibre_beam(index, kUnitBox, 0.02, beam({1, 0, 0}, 16, 3));
  const std::size_t k = c.size() - 1;
  EXPECT_NEAR(c.transmittance(k), 1.0 - std::numbers::pi * r * r, 4.0 * c.stderr_abs(k));
}

TEST(FibreBeam, InternalExtinctionMatchesChordIntegral) {
  const double r = 0.05;
  const double kappa = 20.0;  // 2κr = 2: a fibre's centre transmits e^−2
  const CapsuleIndex index(straight_fibre(0.5, 0.5, r));
  const auto c = measure_fibre_beam(index, kUnitBox, 0.01, beam({0, 0, 1}, 64, 5), kappa);
  for (double t : {0.47, 0.5, 0.53, 1.0}) {
    const std::size_t k = depth_index(c, t);
    const double want = chord_integral(kappa, r, 0.5, c.depth[k], 1.0);
    EXPECT_NEAR(c.transmittance(k), want, 4.0 * c.stderr_abs(k) + 1e-12) << "t = " << t;
  }
  // Zero extinction: transparent fibres.
  const auto clear = measure_fibre_beam(index, kUnitBox, 0.05, beam({0, 0, 1}, 1), 0.0);
  EXPECT_EQ(clear.transmittance(clear.size() - 1), 1.0);
}

TEST(FibreBeam, RegularArrayOfParallelFibres) {
  // Two layers of fibres along x, pitch p, the second shifted by p/2: disjoint shadows of width 2r.
  const double p = 0.1;
  const double r = 0.02;
  FibreSet f;
  for (int m = 0; m < 10; ++m) f.add({{-0.5, (m + 0.5) * p, 0.25}, {1.5, (m + 0.5) * p, 0.25}}, r);
  for (int m = 0; m <= 10; ++m) f.add({{-0.5, m * p, 0.75}, {1.5, m * p, 0.75}}, r);
  const CapsuleIndex index(f);
  const auto z = measure_fibre_beam(index, kUnitBox, 0.01, beam({0, 0, 1}, 8, 11));
  const std::size_t half = depth_index(z, 0.5);
  EXPECT_NEAR(z.transmittance(half), 1.0 - 2.0 * r / p, 4.0 * z.stderr_abs(half));
  EXPECT_NEAR(z.transmittance(z.size() - 1), 1.0 - 4.0 * r / p, 4.0 * z.stderr_abs(z.size() - 1));
  // Across the fibres in their plane (along y): rays in the two layers' bands, 2·2r of the height.
  const auto y = measure_fibre_beam(index, kUnitBox, 0.01, beam({0, 1, 0}, 8, 12));
  EXPECT_NEAR(y.transmittance(y.size() - 1), 1.0 - 4.0 * r, 4.0 * y.stderr_abs(y.size() - 1));
}

/// Mean number of isotropic capsules (length ℓ, radius r, centres uniform in a box of volume V)
/// meeting a ray segment of length t: each does with probability E[vol(segment ⊕ capsule)]/V,
/// the Steiner formula of the parallelogram t×ℓ (angle θ) dilated by r:
/// 2 t ℓ |sin θ| r + π (t + ℓ) r² + 4/3 π r³, with E|sin θ| = π/4 for isotropic directions.
double hit_volume(double t, double ell, double r) {
  return std::numbers::pi / 2.0 * t * ell * r + std::numbers::pi * (t + ell) * r * r +
         4.0 / 3.0 * std::numbers::pi * r * r * r;
}

TEST(FibreBeam, RandomIsotropicFibresFollowTheBooleanLaw) {
  // N fibres with centres uniform in the box padded by ℓ/2 + r (every capsule that can meet a
  // ray inside the box): a ray of length t > 0 is clear with probability (1 − v(t)/V)^N.
  const double ell = 0.2;
  const double r = 0.01;
  const int n = 600;
  const double pad = ell / 2 + r;
  const double vol = std::pow(1.0 + 2 * pad, 3);
  constexpr int kRealizations = 10;
  const std::array<double, 3> depths{0.2, 0.5, 1.0};
  std::array<double, 3> sum{};
  std::array<double, 3> sum2{};
  for (int real = 0; real < kRealizations; ++real) {
    Pcg32 rng = stream_for(2024, static_cast<std::uint64_t>(real));
    FibreSet f;
    for (int i = 0; i < n; ++i) {
      const Point3 c{-pad + (1 + 2 * pad) * rng.uniform(), -pad + (1 + 2 * pad) * rng.uniform(),
                     -pad + (1 + 2 * pad) * rng.uniform()};
      const double uz = 1.0 - 2.0 * rng.uniform();
      const double phi = 2.0 * std::numbers::pi * rng.uniform();
      const double s = std::sqrt(1.0 - uz * uz);
      const Point3 u{s * std::cos(phi), s * std::sin(phi), uz};
      f.add({{c[0] - ell / 2 * u[0], c[1] - ell / 2 * u[1], c[2] - ell / 2 * u[2]},
             {c[0] + ell / 2 * u[0], c[1] + ell / 2 * u[1], c[2] + ell / 2 * u[2]}},
            r);
    }
    const CapsuleIndex index(f);
    const auto c = measure_fibre_beam(index, kUnitBox, 0.02, beam({0, 0, 1}, 4, 100 + real));
    for (std::size_t q = 0; q < depths.size(); ++q) {
      const double t = c.transmittance(depth_index(c, depths[q]));
      sum[q] += t;
      sum2[q] += t * t;
    }
  }
  for (std::size_t q = 0; q < depths.size(); ++q) {
    const double mean = sum[q] / kRealizations;
    const double sd =
        std::sqrt(std::max(0.0, sum2[q] / kRealizations - mean * mean) * kRealizations / (kRealizations - 1));
    const double law = std::pow(1.0 - hit_volume(depths[q], ell, r) / vol, n);
    EXPECT_NEAR(mean, law, 4.0 * sd / std::sqrt(kRealizations)) << "t = " << depths[q];
    EXPECT_GT(sd, 0.0);
  }
}

TEST(FibreBeam, SameBytesForAnyThreadCount) {
  FibreSet f;
  Pcg32 rng = stream_for(9, 0);
  for (int i = 0; i < 200; ++i) {
    const Point3 a{rng.uniform(), rng.uniform(), rng.uniform()};
    f.add({a, {a[0] + 0.2 * rng.uniform(), a[1] + 0.2, a[2] - 0.1 * rng.uniform()}}, 0.01);
  }
  const CapsuleIndex index(f);
  const auto spec = beam({0.3, -0.4, 0.8}, 3, 4);
  volume::TransmittanceCurve one;
  volume::TransmittanceCurve two;
  {
    const ThreadLimit limit(1);
    one = measure_fibre_beam(index, kUnitBox, 0.02, spec, 15.0);
  }
  {
    const ThreadLimit limit(2);
    two = measure_fibre_beam(index, kUnitBox, 0.02, spec, 15.0);
  }
  EXPECT_EQ(one.log_t, two.log_t);
  EXPECT_EQ(one.rel_stderr, two.rel_stderr);
  EXPECT_EQ(one.rays, two.rays);
  EXPECT_LT(one.transmittance(one.size() - 1), 1.0);
}

// A grid over the same world box indexed from far away (the origin moved by −shift·h; only
// its corner voxels active, which set the box): the fibre beam keeps the same rays, with full
// chords too, and gives the same T to the rounding of the box's world corner (origin + h·index).
// Its full chords were tested against world ends that lost the digits the span keeps: here the
// box of the tester's cloth (67 × 67 × 35 voxels from (−6, −6, −17)) at 2²⁹ along z came out
// 7.5e-10 short of its span, past the chord tolerance, and every ray was dropped
// (docs/validate.md "Beams far from index 0").
TEST(FibreBeam, AGridFarFromIndexZeroKeepsTheSameRays) {
  const double h = 0.02;
  // World origins 0 and off 0, as a cloth's.
  Pcg32 origins = stream_for(31, 0);
  for (int trial = 0; trial < 3; ++trial) {
    Point3 o{origins.uniform() - 0.5, origins.uniform() - 0.5, origins.uniform() - 0.5};
    if (trial == 0) o = {0.0, 0.0, 0.0};
    FibreSet f;
    Pcg32 rng = stream_for(12, 0);
    for (int i = 0; i < 600; ++i) {
      const Point3 p{o[0] - 0.12 + 1.34 * rng.uniform(), o[1] - 0.12 + 1.34 * rng.uniform(),
                     o[2] - 0.34 + 0.7 * rng.uniform()};
      f.add({p, {p[0] + 0.2 * rng.uniform(), p[1] + 0.2, p[2] - 0.1 * rng.uniform()}}, 0.01);
    }
    const CapsuleIndex index(f);
    const auto grid_at = [&](const std::array<int, 3>& shift) {
      volume::Grid g(h);
      g.set_origin({o[0] - h * shift[0], o[1] - h * shift[1], o[2] - h * shift[2]});
      for (int c = 0; c < 8; ++c)
        g.set_value(((c & 1) ? 60 : -6) + shift[0], ((c & 2) ? 60 : -6) + shift[1], ((c & 4) ? 17 : -17) + shift[2],
                    0.5f);
      return g;
    };
    const volume::Grid near = grid_at({0, 0, 0});
    for (const std::array<int, 3>& shift : {std::array<int, 3>{1000, -37, 5},
                                            {1 << 30, 5, -(1 << 29)},
                                            {5, -7, (1 << 30) + 3},
                                            {-(1 << 30) - 11, 1 << 30, -(1 << 30) + 17}}) {
      const volume::Grid far = grid_at(shift);
      for (const bool full : {false, true}) {
        for (const std::array<double, 3>& d : {std::array<double, 3>{1.0, 0.0, 2.0}, {-0.3, 0.5, -1.0}}) {
          volume::BeamSpec spec = beam(d, trial % 2 == 0 ? 1 : 3, 7);
          spec.full_chords = full;
          const std::string what =
              fmt::format("origin ({}, {}, {}), shift ({}, {}, {}), {}, full chords {}", o[0], o[1], o[2], shift[0],
                          shift[1], shift[2], volume::direction_label(d), full);
          const auto a = measure_fibre_beam(index, near, spec, kOpaque);
          volume::TransmittanceCurve b;
          ASSERT_NO_THROW(b = measure_fibre_beam(index, far, spec, kOpaque)) << what;
          ASSERT_GT(a.rays, 0U);
          EXPECT_EQ(a.rays, b.rays) << what;
          ASSERT_EQ(a.depth, b.depth) << what;
          for (std::size_t k = 0; k < a.size(); ++k)
            EXPECT_NEAR(a.transmittance(k), b.transmittance(k), 1e-12) << what << " k=" << k;
          EXPECT_LT(a.transmittance(a.size() - 1), 0.9) << what;
        }
      }
    }
  }
}

TEST(FibreBeam, BadInput) {
  FibreSet bad;
  bad.add({{0, 0, 0}, {1, 0, 0}}, -1.0);
  EXPECT_THROW(CapsuleIndex{bad}, Error);
  const CapsuleIndex index(straight_fibre(0.5, 0.5, 0.05));
  EXPECT_THROW((void)measure_fibre_beam(index, kUnitBox, 0.01, beam({0, 0, 1}, 1), -1.0), Error);
  EXPECT_THROW((void)measure_fibre_beam(index, kUnitBox, 0.01, beam({0, 0, 0}, 1)), Error);
  EXPECT_THROW((void)measure_fibre_beam(index, kUnitBox, 0.01, beam({0, 0, 1}, 0)), Error);
}

// A box given by the caller (not a grid's) is checked as Grid.to_numpy checks an index box: an
// inverted one once gave a lattice of one cell and the depths [−1, −1] with T = 1.
TEST(FibreBeam, AnInvertedOrNonFiniteBoxOrABadCellIsRefused) {
  const CapsuleIndex index(straight_fibre(0.5, 0.5, 0.05));
  const auto refused = [&](const volume::WorldBox& box, double cell, std::initializer_list<std::string> words) {
    for (const auto& d : {std::array<double, 3>{0, 0, 1}, std::array<double, 3>{1, 1, 2}}) {
      EXPECT_THAT([&] { (void)measure_fibre_beam(index, box, cell, beam(d, 1)); },
                  weft::test::throws_one_line_error_with(words));
      EXPECT_THAT([&] { check_fibre_beam(box, cell, beam(d, 1)); }, weft::test::throws_one_line_error_with(words));
    }
  };
  const std::initializer_list<std::string> inverted{"fibre beam: box min must be <= max per axis"};
  refused({{1, 1, 1}, {0, 0, 0}}, 0.1, inverted);
  refused({{0, 0, 1}, {1, 1, 0}}, 0.1, inverted);  // one axis is enough
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  refused({{0, nan, 0}, {1, 1, 1}}, 0.1, {"fibre beam: box corners must be finite"});
  refused({{0, 0, 0}, {1, 1, inf}}, 0.1, {"fibre beam: box corners must be finite"});
  refused({{-inf, 0, 0}, {1, 1, 1}}, 0.1, {"fibre beam: box corners must be finite"});
  for (double cell : {0.0, -0.1, nan, inf}) refused(kUnitBox, cell, {"fibre beam: cell width"});
  // A flat box is a box: at its depth 0 nothing is crossed.
  const auto flat = measure_fibre_beam(index, {{0, 0, 0.2}, {1, 1, 0.2}}, 0.1, beam({0, 0, 1}, 1));
  ASSERT_GT(flat.size(), 0U);
  for (std::size_t k = 0; k < flat.size(); ++k) {
    EXPECT_EQ(flat.depth[k], 0.0);
    EXPECT_EQ(flat.transmittance(k), 1.0);
  }
}

// The budget of every pass (volume/pass_budget.h) before any ray: 10⁴ cells × 10⁹ rays each
// would run for days; it is refused at once with the rays and steps named (it once grew to
// 15.7 GB holding each cell's offsets, then ran on).
TEST(FibreBeam, AHugeRayCountIsRefusedBeforeAnyWork) {
  const CapsuleIndex index(straight_fibre(0.5, 0.5, 0.05));
  EXPECT_THAT(
      [&] {
        (void)measure_fibre_beam(index, kUnitBox, 0.01, beam({1, 1, 1}, 1'000'000'000, 3));
      },
      weft::test::throws_one_line_error_with({"fibre beam", "over the fibres", "over the limit of 1e+12"}));
  // The same beam with 16 rays per cell runs (well inside the budget).
  EXPECT_GT(measure_fibre_beam(index, kUnitBox, 0.01, beam({1, 1, 1}, 16, 3)).rays, 0U);
}

}  // namespace
}  // namespace weft::fibres
