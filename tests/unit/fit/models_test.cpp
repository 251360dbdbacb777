// Predictive models (fit/models.h), the statistics scale (fit/scale.h), provenance σ
// (volume/provenance.h): exact cases, predictions independent of the ground truth, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../error_of.h"
#include "test_grids.h"
#include "weft/core/error.h"
#include "weft/fit/models.h"
#include "weft/fit/report.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/volume/beam.h"
#include "weft/volume/provenance.h"

namespace weft::fit {
namespace {

using volume::Grid;

using test::box_grid;
using weft::test::error_of;

std::vector<double> depths_of(const Grid& g, const std::array<double, 3>& d) {
  volume::BeamSpec b;
  b.direction = d;
  return volume::beam_depths(g, b);
}

const PredictedModel& find(const std::vector<PredictedModel>& ms, const std::string& name) {
  for (const auto& m : ms) {
    if (m.name == name) return m;
  }
  throw std::runtime_error("no model " + name);
}

TEST(Models, UniformMediumGivesTheExponentialForEveryModel) {
  const Grid g = box_grid(12, 10, 9, 0.25f, 0.1);
  for (const std::array<double, 3> d : {std::array<double, 3>{1, 0, 0}, {0, -1, 0}, {0, 0, 1}}) {
    for (double L : {0.0, 0.3, 0.45}) {
      PredictionSpec spec;
      spec.direction = d;
      spec.sigma = 3.0;
      spec.scale = L;
      const auto depths = depths_of(g, d);
      const auto models = predict_axis(g, spec, depths);
      ASSERT_GE(models.size(), 7u);
      for (const auto& m : models) {
        for (std::size_t k = 0; k < depths.size(); ++k) {
          EXPECT_NEAR(m.log_t[k], -3.0 * 0.25 * depths[k], 1e-9 * (1.0 + depths[k])) << m.name << " L " << L;
        }
      }
    }
  }
}

TEST(Models, HalfEmptyColumnsAreExactlyAGapLaw) {
  // Columns along x: those with even j hold C = 0.4 over the whole length, the others nothing.
  Grid g(0.1);
  g.set_origin({0, 0, 0});
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 4; ++k) g.set_value(i, j, k, j % 2 == 0 ? 0.4f : 0.0f);
    }
  }
  // Odd rows must still be inside the box: an active zero on the last row keeps the box.
  PredictionSpec spec;
  spec.direction = {1, 0, 0};
  spec.sigma = 2.0;
  spec.scale = 0.3;
  const auto depths = depths_of(g, spec.direction);
  const auto models = predict_axis(g, spec, depths);
  const auto gt = volume::measure_beam(g, {.direction = {1, 0, 0}, .scale = 2.0});
  for (const char* name :
       {"gap-gamma", "empirical"}) {  // exact here; the block models approximate a mixed block by a gamma law
    const auto& m = find(models, name);
    for (std::size_t k = 0; k < depths.size(); ++k) EXPECT_NEAR(m.log_t[k], gt.log_t[k], 1e-9) << name << " k " << k;
  }
  const auto& gap = find(models, "gap-gamma");
  EXPECT_NEAR(gap.parameters[1].second, 0.5, 1e-12);  // gap_fraction
}

TEST(Models, LocalGammaIntegratesTheBlockHazardExactly) {
  // Two blocks of 2 voxels along x (h = 1): the first uniform C = 0.5, the second half of its
  // columns 0.2, half 0.6 (mean 0.4, column-mean variance 0.04). Transverse 2×2 (one coarse column).
  Grid g(1.0);
  g.set_origin({0, 0, 0});
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 2; ++j) {
      for (int k = 0; k < 2; ++k) g.set_value(i, j, k, i < 2 ? 0.5f : (j == 0 ? 0.2f : 0.6f));
    }
  }
  PredictionSpec spec;
  spec.direction = {1, 0, 0};
  spec.sigma = 1.5;
  spec.scale = 2.0;
  const auto depths = depths_of(g, spec.direction);
  const auto models = predict_axis(g, spec, depths);
  const auto& m = find(models, "local-gamma");
  const double mean = static_cast<double>(0.4f);
  const double var = 0.25 * std::pow(static_cast<double>(0.6f) - static_cast<double>(0.2f), 2);
  const double kappa = spec.sigma * var / mean;
  const double alpha = mean * mean / var;
  for (std::size_t k = 0; k < depths.size(); ++k) {
    const double t = depths[k];
    double H = spec.sigma * static_cast<double>(0.5f) * std::min(t, 2.0);
    if (t > 2.0) H += alpha * (std::log1p(kappa * t) - std::log1p(kappa * 2.0));  // memory from entry
    EXPECT_NEAR(m.log_t[k], -H, 1e-6) << "t " << t;                               // fields are stored as float
  }
}

TEST(Models, PredictionsNeverSeeTheGroundTruth) {
  // validate() measures the beam only after predicting; its models equal predict_axis() on the
  // beam's depths bit for bit, and predict_axis has no parameter a curve could come through.
  const Grid g = test::patterned_grid();
  const Validation v = test::validate_patterned(g);
  for (const auto& a : v.axes) {
    PredictionSpec ps;
    ps.direction = a.direction;
    ps.sigma = 4.0;  // as validate_patterned
    ps.scale = 0.2;
    const auto predicted = predict_axis(g, ps, a.ground_truth.depth);
    for (const auto& m : a.models) {
      if (m.uses_ground_truth || m.name == "gamma" || m.name == "isotropic" || m.name == "exponential") continue;
      EXPECT_EQ(m.log_t, find(predicted, m.name).log_t) << a.label << " " << m.name;
    }
    // Only the least-squares reference is marked as using the ground truth.
    for (const auto& m : a.models) EXPECT_EQ(m.uses_ground_truth, m.name == "least-squares") << m.name;
  }
}

TEST(Models, BadInputIsRefused) {
  const Grid g = box_grid(3, 3, 3, 0.5f);
  const auto depths = depths_of(g, {1, 0, 0});
  PredictionSpec spec;
  spec.sigma = 0.0;
  EXPECT_THROW((void)predict_axis(g, spec, depths), Error);
  spec.sigma = 1.0;
  spec.direction = {1, 1, 0};
  EXPECT_THROW((void)predict_axis(g, spec, depths), Error);
  spec.direction = {1, 0, 0};
  spec.scale = -1.0;
  EXPECT_THROW((void)predict_axis(g, spec, depths), Error);
  EXPECT_THROW((void)predict_axis(Grid(1.0), PredictionSpec{}, depths), Error);
}

TEST(Scale, ResolvesNamesFromProvenanceAndVoxels) {
  Grid g = box_grid(20, 20, 20, 0.0f, 0.01);
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      for (int k = 0; k < 20; ++k) g.set_value(i, j, k, ((i / 5 + j / 5 + k / 5) % 2) ? 0.6f : 0.0f);
    }
  }
  volume::Provenance none;
  volume::Provenance p;
  p.yarn_diameter = 0.3;
  EXPECT_DOUBLE_EQ(resolve_scale("yarn", g, p).length[0], 0.3);
  EXPECT_EQ(resolve_scale("yarn", g, p).rule, "yarn");
  EXPECT_THROW((void)resolve_scale("yarn", g, none), Error);  // no silent voxel-dependent default
  const auto measured = resolve_scale("yarn-measured", g, none);
  EXPECT_EQ(measured.rule, "yarn-measured");
  EXPECT_GT(measured.length[0], 0.0);
  EXPECT_EQ(resolve_scale("0.25", g, none).length[2], 0.25);
  EXPECT_EQ(resolve_scale("extent", g, none).length[1], 0.0);
  EXPECT_THROW((void)resolve_scale("yran", g, p), Error);
  EXPECT_THROW((void)resolve_scale("-2", g, p), Error);
  EXPECT_THROW((void)resolve_scale("0", g, p), Error);
}

bool holds(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(Scale, AYarnScaleThatCannotBeMeasuredIsRefusedSayingWhy) {
  const volume::Provenance none;
  // Uniform C: R is 0 at every lag (it was −inf through the 1/e interpolation). A plate one voxel
  // thick has no lag along that axis either.
  for (const Grid& g : {box_grid(4, 4, 4, 0.3f, 0.1), box_grid(1, 10, 10, 0.3f, 0.1)}) {
    const std::string e = error_of([&] { (void)resolve_scale("yarn-measured", g, none); });
    EXPECT_TRUE(holds(e, "yarn scale: cannot be measured on grid 'density': its concentration is uniform")) << e;
    EXPECT_TRUE(holds(e, "pass --window LENGTH")) << e;
    const std::string p =
        error_of([&] { (void)resolve_scale("yarn-measured", g, none, null_progress(), FrontEnd::python); });
    EXPECT_TRUE(holds(p, "pass window=LENGTH")) << p;
  }
  // Slabs along x only: along y and z R stays 1, so the median axis gives only a lower bound.
  Grid slabs = box_grid(8, 8, 8, 0.0f, 0.1);
  for (int i = 0; i < 8; i += 2) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 8; ++k) slabs.set_value(i, j, k, 0.5f);
    }
  }
  const std::string e = error_of([&] { (void)resolve_scale("yarn-measured", slabs, none); });
  EXPECT_TRUE(holds(e, "never falls to 1/e within half the box along y, z")) << e;
  // A plate with structure in its plane is measured from the two axes that have lags.
  Grid plate = box_grid(1, 12, 12, 0.0f, 0.1);
  for (int j = 0; j < 12; ++j) {
    for (int k = 0; k < 12; ++k) plate.set_value(0, j, k, static_cast<float>(((3 * j + 5 * k) % 7) / 10.0));
  }
  const double scale = measured_yarn_scale(plate);
  EXPECT_TRUE(std::isfinite(scale) && scale > 0.0) << scale;
}

TEST(Scale, AClampedWindowIsReportedWithTheLengthUsed) {
  const Grid g = test::patterned_grid();  // 16 x 12 x 6 voxels of 0.05
  StatisticsScale s;
  s.rule = "length";
  s.length.fill(1e-9);
  const ScaleUse tiny = scale_use(s, g, true);
  for (double l : tiny.length) EXPECT_DOUBLE_EQ(l, 0.05);
  ASSERT_EQ(tiny.notes.size(), 2U);
  EXPECT_TRUE(holds(tiny.notes[0], "--window 1e-09 is shorter than half a voxel (0.025) along x, y, z: one voxel"))
      << tiny.notes[0];
  EXPECT_TRUE(holds(tiny.notes[1], "one voxel along x, y, z: the local models")) << tiny.notes[1];
  EXPECT_EQ(scale_use(s, g, false).notes.size(), 1U);  // fit: no local models
  s.length.fill(1e-320);                               // subnormal: echoed as given, not as {:g}'s 9.99989e-321
  const ScaleUse subnormal = scale_use(s, g, false, FrontEnd::cli, kStudyWindowOption);
  ASSERT_EQ(subnormal.notes.size(), 1U);
  EXPECT_TRUE(holds(subnormal.notes[0], "--study-window 1e-320 is shorter than half a voxel")) << subnormal.notes[0];
  s.length.fill(1e9);
  const ScaleUse huge = scale_use(s, g, true, FrontEnd::python);
  EXPECT_DOUBLE_EQ(huge.length[0], 16 * 0.05);
  EXPECT_DOUBLE_EQ(huge.length[2], 6 * 0.05);
  ASSERT_EQ(huge.notes.size(), 1U);
  EXPECT_TRUE(holds(huge.notes[0], "window=1000000000 is longer than the active box along x, y, z")) << huge.notes[0];
  // Within the box: no note; rounding to whole voxels is not a clamp. The length used is the
  // window of the statistics.
  s.length = {0.2, 0.26, 0.0};
  const ScaleUse fits = scale_use(s, g, true);
  EXPECT_TRUE(fits.notes.empty());
  for (int a = 0; a < 3; ++a)
    EXPECT_DOUBLE_EQ(fits.length[static_cast<std::size_t>(a)],
                     window_stats(g, a, s.length[static_cast<std::size_t>(a)]).window);
}

TEST(Scale, AutocorrelationOfAPeriodicFieldHasItsPeriod) {
  // C alternates in slabs of 4 voxels along x: R(l) is a triangle wave, −1 at l = 4, 1 at 8.
  Grid g(1.0);
  g.set_origin({0, 0, 0});
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 4; ++j) {
      for (int k = 0; k < 4; ++k) g.set_value(i, j, k, (i / 4) % 2 ? 1.0f : 0.0f);
    }
  }
  const auto r = autocorrelation(g, 0, 8);
  EXPECT_NEAR(r[0], 1.0, 1e-12);
  EXPECT_NEAR(r[4], -1.0, 0.1);
  EXPECT_NEAR(r[8], 1.0, 0.15);
  EXPECT_NEAR(lag_at_inverse_e(r), 4.0 * (1.0 - std::exp(-1.0)) / 2.0, 0.1);
}

TEST(Provenance, RoundTripsAndDerivesLegacySigma) {
  Grid g = box_grid(2, 2, 2, 0.5f);
  EXPECT_FALSE(volume::read_provenance(g).sigma.has_value());
  volume::Provenance p;
  p.units = "mm";
  p.sigma = 106.1;
  p.sigma_rule = "test";
  p.yarn_diameter = 0.3;
  volume::write_provenance(g, p);
  const auto q = volume::read_provenance(g);
  EXPECT_DOUBLE_EQ(*q.sigma, 106.1);
  EXPECT_DOUBLE_EQ(*q.yarn_diameter, 0.3);
  EXPECT_EQ(q.units, "mm");
  // A grid of an earlier weft: only the generator's JSON.
  Grid legacy = box_grid(2, 2, 2, 0.5f);
  const std::string yarn =
      R"({"fiber_radius":0.006,"ply_offset":0.07,"ply_radius":0.08,"ellipse_n":1.0,"ellipse_b":0.8,"rho_max":1.0})";
  legacy.set_metadata("generator", "{\"warp_yarn\":" + yarn + ",\"weft_yarn\":" + yarn + "}");
  const auto l = volume::read_provenance(legacy);
  EXPECT_NEAR(*l.sigma, 2.0 / (std::numbers::pi * 0.006), 1e-9);
  EXPECT_NEAR(*l.yarn_diameter, 0.3, 1e-12);
  Grid bad = box_grid(2, 2, 2, 0.5f);
  bad.set_metadata("weft:sigma_per_concentration", "-3");
  EXPECT_THROW((void)volume::read_provenance(bad), Error);
  bad.set_metadata("weft:sigma_per_concentration", "nan");
  EXPECT_THROW((void)volume::read_provenance(bad), Error);
}

}  // namespace
}  // namespace weft::fit
