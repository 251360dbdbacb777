// Beams: known column densities give exactly the known T(t); every tracing method gives the same
// optical depths; log-space averaging survives T far below 1e−300; results ignore thread count.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <array>
#include <cmath>
#include <filesystem>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/lattice.h"
#include "weft/volume/scatterer.h"

namespace weft::volume {
namespace {

/// Columns along z with uniform, known values c(i, j) over a 4×3 face and 6 voxels of depth.
Grid known_columns(double h, double (*c)(int, int)) {
  Grid g(h);
  g.set_origin({0.3, -0.2, 1.1});
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 6; ++k) g.set_value(i, j, k, static_cast<float>(c(i, j)));
    }
  }
  return g;
}

double column_value(int i, int j) { return 0.25 * (i + 1) + 0.5 * j; }  // exactly representable in float

TEST(Beam, HandBuiltColumnsGiveExactlyTheKnownTransmittance) {
  const double h = 0.5;
  const double sigma = 3.0;
  const Grid g = known_columns(h, column_value);
  for (BeamMethod method : {BeamMethod::streaming, BeamMethod::per_ray, BeamMethod::openvdb_dda}) {
    for (double sense : {1.0, -1.0}) {
      BeamSpec spec;
      spec.direction = {0.0, 0.0, sense};
      spec.scale = sigma;
      spec.method = method;
      const TransmittanceCurve c = measure_beam(g, spec);
      ASSERT_EQ(c.size(), 7U);
      EXPECT_EQ(c.rays, 12U);
      for (std::size_t k = 0; k < c.size(); ++k) {
        const double t = c.depth[k];
        EXPECT_DOUBLE_EQ(t, std::min(k * h, 6 * h));
        double mean = 0.0;
        double mean2 = 0.0;
        for (int i = 0; i < 4; ++i) {
          for (int j = 0; j < 3; ++j) {
            const double x = std::exp(-sigma * column_value(i, j) * t);
            mean += x / 12.0;
            mean2 += x * x / 12.0;
          }
        }
        EXPECT_NEAR(c.log_t[k], std::log(mean), 1e-12) << to_string(method) << " k=" << k;
        const double se = std::sqrt(std::max(0.0, mean2 - mean * mean) / 11.0) / mean;
        EXPECT_NEAR(c.rel_stderr[k], se, 1e-9) << to_string(method) << " k=" << k;
      }
    }
  }
}

// An axis beam's rays of one column cross the same voxels: 5 rays per column are 12 distinct
// rays over the 4x3 face, for every method; an oblique beam's jittered rays are all distinct.
TEST(Beam, CountsDistinctRaysOfAnAxisBeamOncePerColumn) {
  const Grid g = known_columns(0.5, column_value);
  for (BeamMethod method : {BeamMethod::streaming, BeamMethod::per_ray, BeamMethod::openvdb_dda}) {
    BeamSpec spec;
    spec.direction = {0.0, 0.0, 1.0};
    spec.rays_per_column = 5;
    spec.method = method;
    const TransmittanceCurve c = measure_beam(g, spec);
    EXPECT_EQ(c.rays, 60U) << to_string(method);
    EXPECT_EQ(c.distinct_rays, 12U) << to_string(method);
    spec.rays_per_column = 1;
    const TransmittanceCurve one = measure_beam(g, spec);
    EXPECT_EQ(one.distinct_rays, 12U);
    for (std::size_t k = 0; k < c.size(); ++k) {
      // Same T and standard error (to rounding: 5 copies of each ray are summed).
      EXPECT_NEAR(c.log_t[k], one.log_t[k], 1e-12);
      EXPECT_NEAR(c.rel_stderr[k], one.rel_stderr[k], 1e-12 * one.rel_stderr[k] + 1e-15);
    }
  }
  BeamSpec oblique;
  oblique.direction = {1.0, 1.0, 2.0};
  oblique.rays_per_column = 3;
  const TransmittanceCurve c = measure_beam(g, oblique);
  EXPECT_EQ(c.distinct_rays, c.rays);
  EXPECT_GT(c.rays, 0U);
}

TEST(Beam, FinerDepthStepInterpolatesExactly) {
  const Grid g = known_columns(1.0, column_value);
  BeamSpec spec;
  spec.direction = {0.0, 0.0, 1.0};
  spec.depth_step = 0.3;
  const TransmittanceCurve c = measure_beam(g, spec);
  for (std::size_t k = 0; k < c.size(); ++k) {
    double mean = 0.0;
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 3; ++j) mean += std::exp(-column_value(i, j) * c.depth[k]) / 12.0;
    }
    EXPECT_NEAR(c.log_t[k], std::log(mean), 1e-12);
  }
  EXPECT_DOUBLE_EQ(c.depth.back(), 6.0);
}

TEST(Beam, LogTransmittanceIsRightFarBelowDoubleUnderflow) {
  // τ reaches 6·1e3·0.5·σ = 3e4: T = e^−30000 is 0 in double, log T is not.
  Grid g(0.5);
  for (int i = 0; i < 2; ++i) {
    for (int k = 0; k < 6; ++k) {
      g.set_value(i, 0, k, 1000.0f);
    }
  }
  g.set_value(0, 0, 0, 1000.0f);
  BeamSpec spec;
  spec.direction = {0.0, 0.0, 1.0};
  spec.scale = 10.0;
  const TransmittanceCurve c = measure_beam(g, spec);
  EXPECT_NEAR(c.log_t.back(), -10.0 * 1000.0 * 3.0, 1e-9 * 3e4);
  EXPECT_EQ(c.transmittance(c.size() - 1), 0.0);
  // Two columns with different depths of extinction: the mean is dominated by the lighter one.
  Grid g2(1.0);
  for (int k = 0; k < 4; ++k) {
    g2.set_value(0, 0, k, 200.0f);
    g2.set_value(1, 0, k, 100.0f);
  }
  const TransmittanceCurve c2 = measure_beam(g2, spec);
  const double t = 4.0;
  const double expected = std::log(0.5) + (-10.0 * 100.0 * t) + std::log1p(std::exp(-10.0 * 100.0 * t));
  EXPECT_NEAR(c2.log_t.back(), expected, 1e-9 * std::abs(expected));
}

Grid random_sparse(std::uint64_t seed, int n, double h) {
  Grid g(h);
  g.set_origin({-0.7, 0.4, 2.2});
  Pcg32 rng(seed, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n + 3; ++j) {
      for (int k = 0; k < n - 2; ++k) {
        if (rng.uniform() < 0.3) g.set_value(i + 5, j - 9, k + 1, static_cast<float>(rng.uniform()));
      }
    }
  }
  return g;
}

TEST(Beam, StreamingPerRayAndOpenVdbDdaGiveTheSameOpticalDepths) {
  const Grid g = random_sparse(11, 19, 0.2);
  for (int axis = 0; axis < 3; ++axis) {
    for (double sense : {1.0, -1.0}) {
      BeamSpec spec;
      spec.direction = {0.0, 0.0, 0.0};
      spec.direction[axis] = sense;
      spec.scale = 1.7;
      spec.method = BeamMethod::streaming;
      const BeamDepths a = beam_optical_depths(g, spec);
      spec.method = BeamMethod::per_ray;
      const BeamDepths b = beam_optical_depths(g, spec);
      spec.method = BeamMethod::openvdb_dda;
      const BeamDepths c = beam_optical_depths(g, spec);
      ASSERT_EQ(a.tau.size(), b.tau.size());
      ASSERT_EQ(a.tau.size(), c.tau.size());
      ASSERT_GT(a.tau.size(), 100U);
      for (std::size_t r = 0; r < a.tau.size(); ++r) {
        for (std::size_t k = 0; k < a.depth.size(); ++k) {
          EXPECT_NEAR(a.tau[r][k], b.tau[r][k], 1e-12 * (1 + a.tau[r][k])) << "axis " << axis << " ray " << r;
          EXPECT_NEAR(a.tau[r][k], c.tau[r][k], 1e-12 * (1 + a.tau[r][k])) << "axis " << axis << " ray " << r;
        }
      }
    }
  }
}

TEST(Beam, StreamingMatchesPerRayTransmittanceFarBelowUnderflowAndAcrossActiveTiles) {
  // The streaming beam sums over the active voxels of each face patch (and falls back to dense
  // columns where an active tile overlaps a patch); the per-ray beam averages every ray's own
  // exp(−τ). Same numbers to rounding, from T = 1 down to T ≪ 1e−300 (scale 5000: log T < −1000).
  Grid g = random_sparse(7, 40, 0.2);
  g.impl().grid->tree().addTile(1, openvdb::Coord(8, -8, 8), 0.3f, true);  // one 8³ active tile
  for (double scale : {1.7, 5000.0}) {
    for (int axis = 0; axis < 3; ++axis) {
      for (double sense : {1.0, -1.0}) {
        BeamSpec spec;
        spec.direction = {0.0, 0.0, 0.0};
        spec.direction[axis] = sense;
        spec.scale = scale;
        spec.method = BeamMethod::streaming;
        const TransmittanceCurve a = measure_beam(g, spec);
        spec.method = BeamMethod::per_ray;
        const TransmittanceCurve b = measure_beam(g, spec);
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(a.rays, b.rays);
        if (scale > 100.0) {
          EXPECT_LT(a.log_t.back(), -700.0) << "axis " << axis;  // T < 1e−300
        }
        for (std::size_t k = 0; k < a.size(); ++k) {
          EXPECT_NEAR(a.log_t[k], b.log_t[k], 1e-12 * (1.0 + std::abs(b.log_t[k])))
              << "axis " << axis << " sense " << sense << " scale " << scale << " k=" << k;
          EXPECT_NEAR(a.rel_stderr[k], b.rel_stderr[k], 1e-9 * b.rel_stderr[k] + 1e-15)
              << "axis " << axis << " sense " << sense << " scale " << scale << " k=" << k;
        }
      }
    }
  }
}

TEST(Beam, ObliqueBeamMatchesIndependentPerRayOpticalDepths) {
  const Grid g = random_sparse(5, 9, 0.5);
  BeamSpec spec;
  spec.direction = {0.3, -0.5, 0.8};
  spec.rays_per_column = 2;
  spec.seed = 9;
  const BeamDepths both = beam_optical_depths(g, spec);
  spec.method = BeamMethod::openvdb_dda;
  const BeamDepths ref = beam_optical_depths(g, spec);
  ASSERT_EQ(both.tau.size(), ref.tau.size());
  ASSERT_GT(both.tau.size(), 50U);
  for (std::size_t r = 0; r < both.tau.size(); ++r) {
    for (std::size_t k = 0; k < both.depth.size(); ++k) EXPECT_NEAR(both.tau[r][k], ref.tau[r][k], 1e-10);
  }
  // Every ray starts at its entry point: τ(0) = 0 and τ never decreases.
  for (const auto& row : both.tau) {
    EXPECT_EQ(row.front(), 0.0);
    for (std::size_t k = 1; k < row.size(); ++k) EXPECT_GE(row[k], row[k - 1]);
  }
  EXPECT_THROW((void)measure_beam(g, BeamSpec{{0.3, -0.5, 0.8}, 1.0, 1, false, 1, 0.0, BeamMethod::streaming}), Error);
}

TEST(Beam, ResultDoesNotDependOnThreadCount) {
  const Grid g = random_sparse(3, 24, 0.1);
  for (const auto& dir : {std::array<double, 3>{0, 1, 0}, std::array<double, 3>{1, 1, 0.5}}) {
    BeamSpec spec;
    spec.direction = dir;
    spec.rays_per_column = 2;
    TransmittanceCurve one;
    TransmittanceCurve two;
    {
      const ThreadLimit limit(1);
      one = measure_beam(g, spec);
    }
    {
      const ThreadLimit limit(2);
      two = measure_beam(g, spec);
    }
    ASSERT_EQ(one.size(), two.size());
    for (std::size_t k = 0; k < one.size(); ++k) {
      EXPECT_EQ(one.log_t[k], two.log_t[k]);
      EXPECT_EQ(one.rel_stderr[k], two.rel_stderr[k]);
    }
  }
}

// The same voxels in the same place in the world, indexed from elsewhere (the origin moved by
// −shift·h): the depths are the same doubles, and T the same bytes for the per-ray walk, with
// every chord or full chords only. Depths came from hi − lo of world coordinates, which lost the
// digits the two share (a duplicate last depth at 10⁸); the ray walk ran in index coordinates
// ~2²⁹, whose rounding moved T by ~1e-8, and the full chords' test compared world ends against
// the grid's exact span, which dropped every ray. Shifts that are not multiples of 8 put the
// tree's leaves elsewhere along the rays (docs/validate.md "Beams far from index 0").
TEST(Beam, ShiftedIndexOriginGivesTheSameBytes) {
  const Grid near = random_sparse(5, 17, 0.02);
  const double h = near.voxel_size();
  using Shift = std::array<std::int64_t, 3>;
  for (const Shift& n :
       {Shift{10'000'000, 10'000'000, -10'000'000}, Shift{1000, -37, 5},
        Shift{(std::int64_t{1} << 30) + 3, 5, -(std::int64_t{1} << 29)}, Shift{-2'000'000'000, 100'000'000, 7}}) {
    Grid far(h);
    const auto o = near.origin();
    far.set_origin({o[0] - static_cast<double>(n[0]) * h, o[1] - static_cast<double>(n[1]) * h,
                    o[2] - static_cast<double>(n[2]) * h});
    for (auto it = near.impl().grid->cbeginValueOn(); it; ++it) {
      const auto c = it.getCoord();
      far.set_value(static_cast<int>(c.x() + n[0]), static_cast<int>(c.y() + n[1]), static_cast<int>(c.z() + n[2]),
                    *it);
    }
    for (const auto& dir :
         {std::array<double, 3>{1, 0, 0}, std::array<double, 3>{0, -1, 0}, std::array<double, 3>{0, 0, 1},
          std::array<double, 3>{1, 1, 1}, std::array<double, 3>{-1, 0, 2}, std::array<double, 3>{0.3, -1, 0.2}}) {
      for (const bool full : {false, true}) {
        if (full && beam_axis(dir) >= 0) continue;
        BeamSpec spec;
        spec.direction = dir;
        spec.full_chords = full;
        spec.rays_per_column = beam_axis(dir) >= 0 ? 1 : 3;
        spec.method = BeamMethod::per_ray;
        const TransmittanceCurve a = measure_beam(near, spec);
        const TransmittanceCurve b = measure_beam(far, spec);
        const std::string what = fmt::format("shift ({}, {}, {}), direction {}, full chords {}", n[0], n[1], n[2],
                                             direction_label(dir), full);
        ASSERT_GT(a.rays, 0U) << what;
        EXPECT_EQ(a.rays, b.rays) << what;
        ASSERT_EQ(a.depth, b.depth) << what;
        EXPECT_EQ(a.log_t, b.log_t) << what;
        EXPECT_EQ(a.rel_stderr, b.rel_stderr) << what;
      }
    }
  }
}

// Full chords keep the rays whose chord is the whole depth grid: their number is the lattice's
// full_chord_area over the cell area (up to the cells its edges cut), each is as long as the
// depth grid, and every other ray is shorter. Exactly 45° across a square face leaves only the
// diagonal with the whole depth: refused before anything is traced, wherever the box sits.
TEST(Beam, FullChordsKeepTheRaysWithTheWholeDepthAndRefuseATie) {
  const double h = 0.02;
  const auto box_at = [&](double x0, std::array<double, 3> size) {
    WorldBox b;
    for (std::size_t a = 0; a < 3; ++a) {
      b.lo[a] = x0 + 0.1 * static_cast<double>(a);
      b.hi[a] = b.lo[a] + size[a];
      b.span[a] = size[a];
    }
    return b;
  };
  for (const double x0 : {0.0, 5.4e6}) {
    const WorldBox slab = box_at(x0, {1.2, 0.9, 0.3});
    BeamSpec spec;
    spec.direction = {0.4, -0.3, 1.0};
    spec.full_chords = true;
    const BeamLattice L = make_beam_lattice(slab, h, spec, false);
    std::int64_t kept = 0;
    for (std::int64_t i = 0; i < L.na; ++i) {
      for (std::int64_t j = 0; j < L.nb; ++j) {
        const BeamLattice::Chord c = L.chord(L.ray_offset(i, j, 0.5, 0.5));
        if (!c.hit) continue;
        if (L.traces_chord(c)) {
          ++kept;
          EXPECT_NEAR(c.t_exit - c.t_enter, L.depth_length, 1e-9 * L.depth_length);
        } else {
          EXPECT_LT(c.t_exit - c.t_enter, L.depth_length * (1.0 - 1e-12));
        }
      }
    }
    // The kept cells tile the area up to the ones its perimeter cuts (~perimeter / h).
    const double expected = L.full_chord_area / (h * h);
    EXPECT_NEAR(static_cast<double>(kept), expected, 2.0 * 4.0 * std::sqrt(L.full_chord_area) / h + 4.0) << x0;
    EXPECT_GT(expected, 100.0);

    // Square face, exactly 45°: a tie of the x and y faces.
    const WorldBox square = box_at(x0, {0.8, 0.8, 0.24});
    for (const auto& dir :
         {std::array<double, 3>{1, 1, 0}, std::array<double, 3>{-1, 1, 0}, std::array<double, 3>{1, 0, 0.2}}) {
      BeamSpec tie;
      tie.direction = dir;
      tie.full_chords = true;
      const bool ties = dir[2] == 0.0;
      EXPECT_EQ(full_chord_problem(square, h, tie).empty(), !ties) << direction_label(dir);
      if (ties) {
        EXPECT_THROW((void)make_beam_lattice(square, h, tie, false), Error);
        tie.full_chords = false;
        EXPECT_NO_THROW((void)make_beam_lattice(square, h, tie, false));
      }
    }
    // Nearly 45°: an area narrower than one lattice ray's share is refused too, and more rays per
    // cell bring it back.
    BeamSpec thin;
    thin.direction = {1.0, 1.0 + 1e-3, 0.0};
    thin.full_chords = true;
    EXPECT_FALSE(full_chord_problem(square, h, thin).empty());
    thin.rays_per_column = 64;
    EXPECT_TRUE(full_chord_problem(square, h, thin).empty());
  }
}

TEST(Beam, RejectsBadSpecsAndEmptyGrids) {
  const Grid empty(1.0);
  EXPECT_THROW((void)measure_beam(empty, BeamSpec{}), Error);
  const Grid g = known_columns(1.0, column_value);
  BeamSpec bad;
  bad.scale = -1.0;
  EXPECT_THROW((void)measure_beam(g, bad), Error);
  bad = BeamSpec{};
  bad.rays_per_column = 0;
  EXPECT_THROW((void)measure_beam(g, bad), Error);
  bad = BeamSpec{};
  bad.direction = {0, 0, 0};
  EXPECT_THROW((void)measure_beam(g, bad), Error);
}

TEST(Beam, ParsesDirections) {
  EXPECT_EQ(parse_direction("x"), (std::array<double, 3>{1, 0, 0}));
  EXPECT_EQ(parse_direction("-y"), (std::array<double, 3>{0, -1, 0}));
  EXPECT_EQ(parse_direction("+z"), (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(parse_direction("1,2,3"), (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(parse_direction(" 1, 2 ,\t3 "), (std::array<double, 3>{1, 2, 3}));  // blanks dropped, as for numbers
  EXPECT_EQ(parse_direction(" -y "), (std::array<double, 3>{0, -1, 0}));
  EXPECT_EQ(beam_axis({0.0, -0.0, -2.0}), 2);
  EXPECT_EQ(beam_axis({0.1, 0.0, -2.0}), -1);
  for (const char* bad : {"w", "1,2", "0,0,0", "a,b,c", "1,2,3,4", "nan,0,1", "1,,2", " , , ", "1,0,0,", "1,0,0, "}) {
    EXPECT_THROW((void)parse_direction(bad), Error) << bad;
  }
}

TEST(Beam, ScattererAndSourceRaysAgreeInAUniformMedium) {
  // Origins ∝ C are uniform when C is: T_S and T_Q are the same law, so the two estimates must
  // agree within their standard errors (5σ of the difference of independent means).
  Grid g(1.0);
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 8; ++k) g.set_value(i, j, k, 0.5f);
    }
  }
  ScattererSpec spec;
  spec.rays = 4000;
  spec.seed = 4;
  const ScattererCurves c = measure_scatterer(g, spec);
  EXPECT_NEAR(c.mean_extinction, 0.5, 1e-12);
  EXPECT_EQ(c.t_s.log_t.front(), 0.0);
  for (std::size_t k = 0; k < c.t_s.size(); k += 3) {
    const double se = std::hypot(c.t_s.stderr_abs(k), c.t_q.stderr_abs(k));
    EXPECT_NEAR(c.t_s.transmittance(k), c.t_q.transmittance(k), 5.0 * se + 1e-12) << "k=" << k;
  }
}

// The same cloth stored at another index origin (whole-voxel shifts, the world origin moved
// back; voxels of 1/32 keep every position exact) draws the same particle and source origins
// for the same seed: the same curves to rounding (docs/validate.md "Particle origins in order of
// position"; the tree's leaf order would differ).
TEST(Scatterer, ShiftingTheIndexOriginGivesTheSameCurves) {
  const double h = 1.0 / 32.0;
  const auto grid_at = [&](const std::array<int, 3>& shift) {
    Grid g(h);
    for (int i = 0; i < 20; ++i)
      for (int j = 0; j < 20; ++j)
        for (int k = 0; k < 20; ++k)
          if ((i * 7 + j * 3 + k * 5) % 4 != 0)
            g.set_value(i + shift[0], j + shift[1], k + shift[2],
                        0.2f + 0.1f * static_cast<float>((i + 2 * j + k) % 5));
    g.set_origin({-h * shift[0], -h * shift[1], -h * shift[2]});
    return g;
  };
  ScattererSpec spec;
  spec.rays = 3000;
  spec.seed = 9;
  spec.scale = 12.0;
  spec.fixed_direction = true;
  spec.direction = {1.0, 2.0, 3.0};
  const ScattererCurves base = measure_scatterer(grid_at({0, 0, 0}), spec);
  // The voxel walk runs in index coordinates, (x − origin)/h, whose rounding depends on the index
  // origin; the draws are the same, so the curves agree to that rounding, far below the 1e-2
  // of other draws at these 3000 rays (kRounding is a relative bound on log T, |log T| < 1).
  constexpr double kRounding = 1e-12;
  for (const std::array<int, 3> shift : {std::array<int, 3>{5, -7, 13}, {-3, 1, 2}}) {
    const ScattererCurves moved = measure_scatterer(grid_at(shift), spec);
    EXPECT_EQ(moved.mean_extinction, base.mean_extinction) << shift[0];
    ASSERT_EQ(moved.t_s.size(), base.t_s.size());
    for (std::size_t k = 0; k < base.t_s.size(); ++k) {
      EXPECT_NEAR(moved.t_s.log_t[k], base.t_s.log_t[k], kRounding) << shift[0] << " k=" << k;
      EXPECT_NEAR(moved.t_q.log_t[k], base.t_q.log_t[k], kRounding) << shift[0] << " k=" << k;
    }
  }
}

}  // namespace
}  // namespace weft::volume
