// Coarse models along a ray: closed forms for a constant field, the exponential model equals the
// beam through the downsampled grid, and the sweep's table holds what it promises.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/fit/local_fields.h"
#include "weft/study/sweep.h"
#include "weft/volume/beam.h"
#include "weft/volume/downsample.h"
#include "weft/volume/grid.h"

namespace weft::study {
using namespace weft::fit;  // NOLINT(google-build-using-namespace)
namespace {

using volume::Grid;

/// 8×8×8 fine voxels whose value depends on (i mod 2, j mod 2) only: every 2³ block has the same
/// mean and the same variance of its z column means.
Grid periodic_grid(double h) {
  Grid g(h);
  g.set_origin({0.0, 0.0, 0.0});
  const float v[2][2] = {{0.1f, 0.7f}, {0.3f, 0.5f}};
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 8; ++k) g.set_value(i, j, k, v[i % 2][j % 2]);
    }
  }
  return g;
}

TEST(CoarseBeam, ConstantFieldGivesTheClosedFormsOfEachComposition) {
  const double h = 0.1;
  const double sigma = 3.0;
  const Grid fine = periodic_grid(h);
  const LocalFields fields = local_fields(fine, 2);
  // Block statistics from the four values: mean 0.4, population variance 0.05.
  const double mean = 0.4;
  const double exact_var = (0.09 + 0.09 + 0.01 + 0.01) / 4.0;
  EXPECT_NEAR(fields.mean.value(1, 2, 3), mean, 1e-7);
  // Stored as half (docs/render.md §5b "Storage"): within its rounding; the closed forms below
  // are those of the stored value.
  const double var = fields.variance[2].value(1, 2, 3);
  EXPECT_NEAR(var, exact_var, std::ldexp(exact_var, -11));
  const double alpha = mean * mean / var;
  const double beta = mean / var;
  const auto box = fine.active_bbox();
  const std::array<double, 3> z{0.0, 0.0, 1.0};
  const auto memory = coarse_beam_log_t(fields.mean, &fields.variance[2], box, h, 2, z, sigma, CoarseLaw::gamma_memory);
  const auto indep =
      coarse_beam_log_t(fields.mean, &fields.variance[2], box, h, 2, z, sigma, CoarseLaw::gamma_independent);
  const auto expo = coarse_beam_log_t(fields.mean, nullptr, box, h, 2, z, sigma, CoarseLaw::exponential);
  ASSERT_EQ(memory.size(), 9U);
  for (std::size_t k = 0; k < memory.size(); ++k) {
    const double t = h * static_cast<double>(k);
    // Memory along the whole ray: the homogeneous gamma law (1 + σt/β)^−α (Eq. 20).
    EXPECT_NEAR(memory[k], -alpha * std::log1p(sigma * t / beta), 1e-6) << k;
    // Independent voxels: one factor (1 + σ·2h/β)^−α per whole voxel, the partial one last.
    const double whole = std::floor(static_cast<double>(k) / 2.0);
    const double rest = t - whole * 2.0 * h;
    EXPECT_NEAR(indep[k], -alpha * (whole * std::log1p(sigma * 2.0 * h / beta) + std::log1p(sigma * rest / beta)), 1e-6)
        << k;
    EXPECT_NEAR(expo[k], -sigma * mean * t, 1e-6) << k;
  }
  // Independence forgets: beyond one voxel the product lets less light through than the
  // homogeneous law of the same statistics, and both more than the exponential (Jensen).
  for (std::size_t k = 3; k < memory.size(); ++k) {
    EXPECT_LT(indep[k], memory[k]);
    EXPECT_GT(indep[k], expo[k]);
  }
}

TEST(CoarseBeam, ZeroVarianceIsExponentialAndFactorOneIsTheFineBeam) {
  Grid fine(0.05);
  fine.set_origin({0.2, 0.0, -0.1});
  Pcg32 rng(4, 1);
  for (int i = -3; i < 10; ++i) {
    for (int j = 1; j < 12; ++j) {
      for (int k = -6; k < 5; ++k) {
        if (rng.uniform() < 0.5) fine.set_value(i, j, k, static_cast<float>(rng.uniform()));
      }
    }
  }
  const auto box = fine.active_bbox();
  for (const std::array<double, 3>& d : {std::array<double, 3>{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}) {
    volume::BeamSpec spec;
    spec.direction = d;
    spec.scale = 7.0;
    const auto ref = volume::measure_beam(fine, spec);
    // Factor 1: the coarse grid holds the fine voxels (re-indexed from the box's corner, as every
    // coarse grid: volume/block_lattice.h), so the model is the ground truth itself.
    const Grid one = volume::downsample(fine, 1);
    const auto same = coarse_beam_log_t(one, nullptr, box, 0.05, 1, d, 7.0, CoarseLaw::exponential);
    ASSERT_EQ(same.size(), ref.size());
    for (std::size_t k = 0; k < ref.size(); ++k) EXPECT_NEAR(same[k], ref.log_t[k], 1e-10 * (1 + std::abs(same[k])));
    // A zero variance field makes both gamma compositions the exponential law.
    Grid zero(0.05);
    zero.set_origin(fine.origin());
    for (auto it = box.min[0]; it <= box.max[0]; ++it) zero.set_value(it, box.min[1], box.min[2], 0.0f);
    const auto g = coarse_beam_log_t(one, &zero, box, 0.05, 1, d, 7.0, CoarseLaw::gamma_independent);
    const auto m = coarse_beam_log_t(one, &zero, box, 0.05, 1, d, 7.0, CoarseLaw::gamma_memory);
    for (std::size_t k = 0; k < ref.size(); ++k) {
      EXPECT_EQ(g[k], same[k]);
      EXPECT_NEAR(m[k], same[k], 1e-12 * (1 + std::abs(same[k])));
    }
  }
}

TEST(CoarseBeam, ExponentialModelIsTheBeamThroughTheDownsampledGrid) {
  // Box aligned to the blocks with divisible extents: every coarse column is 4×4 fine columns.
  Grid fine(0.1);
  Pcg32 rng(9, 2);
  for (int i = 0; i < 16; ++i) {
    for (int j = -8; j < 8; ++j) {
      for (int k = 4; k < 24; ++k)
        fine.set_value(i, j, k, static_cast<float>(rng.uniform() < 0.3 ? rng.uniform() : 0.0));
    }
  }
  const Grid coarse = volume::downsample(fine, 4);
  for (const std::array<double, 3>& d : {std::array<double, 3>{0, 1, 0}, {0, 0, 1}, {-1, 0, 0}}) {
    volume::BeamSpec spec;
    spec.direction = d;
    spec.scale = 5.0;
    spec.depth_step = 0.1;
    const auto beam = volume::measure_beam(coarse, spec);
    const auto model = coarse_beam_log_t(coarse, nullptr, fine.active_bbox(), 0.1, 4, d, 5.0, CoarseLaw::exponential);
    ASSERT_EQ(model.size(), beam.size());
    for (std::size_t k = 0; k < model.size(); ++k)
      EXPECT_NEAR(model[k], beam.log_t[k], 1e-9 * (1 + std::abs(model[k])));
  }
}

TEST(Sweep, TableHoldsEveryMethodFactorAndAxisWithSaneNumbers) {
  Grid fine(0.02);
  Pcg32 rng(12, 5);
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 36; ++j) {
      for (int k = 0; k < 20; ++k) {
        // Slabs of fibre-like rods along x: strongly correlated along x, gappy across.
        if ((j / 4 + k / 5) % 2 == 0 && rng.uniform() < 0.9) fine.set_value(i, j, k, 0.6f);
      }
    }
  }
  SweepSpec spec;
  spec.sigma = 20.0;
  spec.factors = {2, 4};
  spec.repetitions = 1;
  const Sweep s = sweep(fine, spec);
  ASSERT_EQ(s.rows.size(), 3U * (3 + 3 * 2));
  std::set<std::string> seen;
  for (const auto& r : s.rows) {
    seen.insert(r.axis + " " + r.method + " " + std::to_string(r.factor) + " " + std::to_string(r.ray_fraction));
    EXPECT_TRUE(std::isfinite(r.error_rms_t));
    EXPECT_GE(r.error_rms_t, 0.0);
    EXPECT_LE(r.error_rms_t, r.error_max_t);
    EXPECT_LE(r.error_max_t, 1.0);
    EXPECT_GT(r.transport_seconds, 0.0);
    if (r.method == "ground-truth" && r.ray_fraction == 1.0) {
      EXPECT_EQ(r.error_rms_t, 0.0);
    }
    if (r.method != "ground-truth") {
      EXPECT_GT(r.prepare_seconds, 0.0);
    }
  }
  EXPECT_EQ(seen.size(), s.rows.size());  // no duplicates
  for (const char* axis : {"+x", "+y", "+z"}) {
    int front = 0;
    for (const auto& r : s.rows) front += (r.axis == axis && r.pareto) ? 1 : 0;
    EXPECT_GE(front, 1) << axis;
  }
  SweepSpec bad = spec;
  bad.factors = {1};
  EXPECT_THROW((void)sweep(fine, bad), Error);
  bad = spec;
  bad.repetitions = 0;
  EXPECT_THROW((void)sweep(fine, bad), Error);
  EXPECT_THROW((void)sweep(Grid(1.0), spec), Error);
}

TEST(Sweep, ParetoFrontKeepsOnlyUndominatedRows) {
  std::vector<SweepRow> rows(4);
  const double secs[] = {1.0, 2.0, 3.0, 0.5};
  const double acc[] = {0.1, 0.05, 0.2, 0.3};
  for (std::size_t i = 0; i < 4; ++i) {
    rows[i].axis = "+z";
    rows[i].transport_seconds = secs[i];
    rows[i].accuracy_rms_t = acc[i];
  }
  mark_pareto(rows);
  EXPECT_TRUE(rows[0].pareto);
  EXPECT_TRUE(rows[1].pareto);
  EXPECT_FALSE(rows[2].pareto);  // slower and worse than row 0
  EXPECT_TRUE(rows[3].pareto);   // fastest
}

}  // namespace
}  // namespace weft::study
