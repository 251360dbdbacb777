// Moment statistics and the gamma model: degenerate cases exact, known moments reproduced,
// least squares recovers a gamma curve, local fields per block.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "test_grids.h"
#include "weft/core/error.h"
#include "weft/fit/gamma_moments.h"
#include "weft/fit/least_squares.h"
#include "weft/fit/local_fields.h"
#include "weft/fit/scale.h"
#include "weft/fit/window_stats.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::fit {
namespace {

using volume::Grid;

using test::box_grid;

volume::TransmittanceCurve beam(const Grid& g, int axis, double sigma) {
  volume::BeamSpec spec;
  spec.direction = {0.0, 0.0, 0.0};
  spec.direction[static_cast<std::size_t>(axis)] = 1.0;
  spec.scale = sigma;
  return volume::measure_beam(g, spec);
}

TEST(Fit, UniformMediumIsExactlyExponential) {
  const Grid g = box_grid(5, 6, 7, 0.3f, 0.1);
  for (int axis = 0; axis < 3; ++axis) {
    for (double window : {0.0, 0.2, 0.35}) {
      const ConcentrationStats s = window_stats(g, axis, window);
      EXPECT_EQ(s.variance, 0.0) << "axis " << axis << " window " << window;
      EXPECT_DOUBLE_EQ(s.mean, static_cast<double>(0.3f));
      const GammaFit fit = gamma_from_moments(s.mean, s.variance, 2.0);
      EXPECT_TRUE(fit.exponential());
      const auto law = model_law(fit);
      EXPECT_EQ(law->name(), "exponential");
      const auto gt = beam(g, axis, 2.0);
      const CurveError e = compare(gt, log_curve(*law, gt.depth));
      EXPECT_LT(e.max_abs_log_t, 1e-12);
    }
  }
}

TEST(Fit, ZeroConcentrationIsAVacuum) {
  const Grid g = box_grid(3, 3, 3, 0.0f);
  const ConcentrationStats s = window_stats(g, 2);
  EXPECT_EQ(s.mean, 0.0);
  EXPECT_EQ(s.variance, 0.0);
  const GammaFit fit = gamma_from_moments(s.mean, s.variance, 5.0);
  EXPECT_TRUE(fit.vacuum());
  const auto law = model_law(fit);
  for (double t : {0.0, 1.0, 1e6}) EXPECT_EQ(law->transmittance(t), 1.0);
}

TEST(Fit, OneNonZeroVoxel) {
  // Alone, the voxel is a uniform medium: exponential with its own value.
  Grid single(0.5);
  single.set_value(2, -1, 4, 0.8f);
  for (int axis = 0; axis < 3; ++axis) {
    const ConcentrationStats s = window_stats(single, axis);
    EXPECT_EQ(s.samples, 1U);
    EXPECT_DOUBLE_EQ(s.mean, static_cast<double>(0.8f));
    EXPECT_EQ(s.variance, 0.0);
  }
  // Inside a 3³ box of active zeros: along z the 9 columns have means v/3 once and 0 eight times.
  Grid g = box_grid(3, 3, 3, 0.0f);
  const double v = 0.9;
  g.set_value(1, 1, 1, static_cast<float>(v));
  const double vf = static_cast<double>(static_cast<float>(v));
  const ConcentrationStats s = window_stats(g, 2);
  EXPECT_EQ(s.samples, 9U);
  EXPECT_NEAR(s.mean, vf / 27.0, 1e-15);
  EXPECT_NEAR(s.variance, (vf / 3.0) * (vf / 3.0) / 9.0 - (vf / 27.0) * (vf / 27.0), 1e-15);
  const GammaFit fit = gamma_from_moments(s.mean, s.variance, 1.0);
  EXPECT_NEAR(fit.alpha, 1.0 / 8.0, 1e-12);  // C̄²/Var = (1/27²)/((1/81)(1/9 − 1/81)... ) = 1/8
}

TEST(Fit, WindowLargerThanTheGridIsClampedToIt) {
  Grid g = box_grid(4, 4, 6, 0.2f, 0.25);
  g.set_value(0, 0, 0, 0.7f);
  const ConcentrationStats full = window_stats(g, 2);
  const ConcentrationStats huge = window_stats(g, 2, 1e6);
  EXPECT_EQ(huge.window_voxels, 6);
  EXPECT_DOUBLE_EQ(huge.window, 1.5);
  EXPECT_EQ(huge.mean, full.mean);
  EXPECT_EQ(huge.variance, full.variance);
  EXPECT_THROW((void)window_stats(g, 2, -1.0), Error);
  EXPECT_THROW((void)window_stats(g, 3), Error);
  EXPECT_THROW((void)window_stats(Grid(1.0), 0), Error);
}

TEST(Fit, SlidingWindowsOfKnownColumnsGiveKnownMoments) {
  // One column along z with values 0,1,2,3,4,5 (×0.125): windows of 2 have means
  // 0.5,1.5,2.5,3.5,4.5 (×0.125): mean 2.5·0.125, variance 2·0.125².
  Grid g(1.0);
  for (int k = 0; k < 6; ++k) g.set_value(0, 0, k, 0.125f * static_cast<float>(k));
  const ConcentrationStats s = window_stats(g, 2, 2.0);
  EXPECT_EQ(s.samples, 5U);
  EXPECT_EQ(s.window_voxels, 2);
  EXPECT_NEAR(s.mean, 2.5 * 0.125, 1e-15);
  EXPECT_NEAR(s.variance, 2.0 * 0.125 * 0.125, 1e-15);
  // Prefix-sum path (many long windows): windows of 4 have means 1.5, 2.5, 3.5 (×0.125).
  Grid long_col(1.0);
  for (int k = 0; k < 200; ++k) long_col.set_value(0, 0, k, static_cast<float>(k % 2));
  const ConcentrationStats p = window_stats(long_col, 2, 100.0);
  EXPECT_EQ(p.samples, 101U);
  // Windows of 100 alternating voxels: always 50 ones.
  EXPECT_NEAR(p.mean, 0.5, 1e-15);
  EXPECT_NEAR(p.variance, 0.0, 1e-28);
}

TEST(Fit, CorrelationLengthOfAKnownColumn) {
  // Runs of two: + + − − + + − − about the mean. Lag 1 has 7 pairs summing to +1 (in d²), so
  // R(1) = 1/7 < 1/e and the 1/e crossing is at (1 − 1/e)/(1 − 1/7) voxels.
  Grid g(0.5);
  const float a = 0.25f;
  const float b = 0.75f;
  for (int k = 0; k < 8; ++k) g.set_value(0, 0, k, (k / 2) % 2 == 0 ? a : b);
  const double expected = 0.5 * (1.0 - std::exp(-1.0)) / (1.0 - 1.0 / 7.0);
  EXPECT_NEAR(correlation_length(g, 2), expected, 1e-12);
  // A uniform medium has no fluctuation to correlate: the window is the whole extent.
  EXPECT_DOUBLE_EQ(correlation_length(box_grid(3, 3, 5, 0.4f, 0.2), 2), 1.0);
  // Layers along z are perfectly correlated along x: never decorrelates, whole extent.
  Grid layers(1.0);
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < 4; ++k) layers.set_value(i, 0, k, k % 2 == 0 ? 0.1f : 0.9f);
  }
  EXPECT_DOUBLE_EQ(correlation_length(layers, 0), 6.0);
}

TEST(Fit, GammaMomentsAndTheirLaw) {
  const GammaFit g = gamma_from_moments(0.4, 0.08, 3.0);
  EXPECT_DOUBLE_EQ(g.alpha, 2.0);
  EXPECT_DOUBLE_EQ(g.beta, 5.0);
  const auto law = model_law(g);
  EXPECT_EQ(law->name(), "gamma");
  for (double t : {0.0, 0.1, 1.0, 10.0, 1e5}) {
    EXPECT_NEAR(law->log_transmittance(t), -2.0 * std::log1p(3.0 * t / 5.0), 1e-12 * (1 + t));
  }
  EXPECT_NEAR(exponential_law(g)->log_transmittance(2.0), -0.4 * 3.0 * 2.0, 1e-15);
  EXPECT_THROW((void)gamma_from_moments(-0.1, 0.1, 1.0), Error);
  EXPECT_THROW((void)gamma_from_moments(0.1, NAN, 1.0), Error);
  EXPECT_THROW((void)gamma_from_moments(0.1, 0.1, 0.0), Error);
}

TEST(Fit, AZeroMeanHoldsNoVariance) {
  // C ≥ 0 with mean 0 is 0 everywhere: a variance with it is impossible, not a vacuum to drop it for.
  EXPECT_TRUE(gamma_from_moments(0.0, 0.0, 10.0).vacuum());
  try {
    (void)gamma_from_moments(0.0, 0.1, 10.0);
    ADD_FAILURE() << "mean 0 with variance 0.1 was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mean concentration 0 with variance 0.1 is impossible"), std::string::npos)
        << e.what();
  }
}

TEST(Fit, PoolWeighsAxesEqually) {
  ConcentrationStats a;
  a.mean = 0.2;
  a.variance = 0.01;
  ConcentrationStats b;
  b.mean = 0.4;
  b.variance = 0.03;
  const ConcentrationStats p = pool({a, b});
  EXPECT_NEAR(p.mean, 0.3, 1e-15);
  EXPECT_NEAR(p.variance, 0.02 + 0.01, 1e-15);  // mean of variances + spread of the means
}

TEST(Fit, LeastSquaresRecoversAGammaCurve) {
  const double sigma = 2.0;
  const double alpha = 0.7;
  const double beta = 3.0;
  volume::TransmittanceCurve c;
  for (int k = 0; k <= 60; ++k) {
    const double t = 0.05 * k;
    c.depth.push_back(t);
    c.log_t.push_back(-alpha * std::log1p(sigma * t / beta));
    c.rel_stderr.push_back(0.0);
  }
  const GammaFit start = gamma_from_moments(0.5, 0.5, sigma);
  const LeastSquaresFit f = fit_gamma_to_curve(c, sigma, start);
  EXPECT_TRUE(f.converged);
  EXPECT_NEAR(f.fit.alpha, alpha, 1e-6);
  EXPECT_NEAR(f.fit.beta, beta, 1e-5);
  EXPECT_LT(f.rms, 1e-9);
  // From a degenerate (exponential) start as well.
  const LeastSquaresFit g = fit_gamma_to_curve(c, sigma, gamma_from_moments(0.3, 0.0, sigma));
  EXPECT_NEAR(g.fit.alpha, alpha, 1e-5);
}

TEST(Fit, CompareMeasuresErrorsAndBias) {
  volume::TransmittanceCurve gt;
  gt.depth = {0.0, 1.0, 2.0};
  gt.log_t = {0.0, -1.0, -2.0};
  gt.rel_stderr = {0, 0, 0};
  const CurveError e = compare(gt, {0.0, -1.5, -3.0});
  EXPECT_NEAR(e.max_abs_log_t, 1.0, 1e-15);
  EXPECT_NEAR(e.rms_abs_log_t, std::sqrt((0.25 + 1.0) / 3.0), 1e-15);
  EXPECT_NEAR(e.mean_log_bias, -0.5, 1e-15);
  EXPECT_EQ(e.below_fraction, 1.0);
  EXPECT_NEAR(e.max_abs_t, std::exp(-1.0) - std::exp(-1.5), 1e-15);
}

// A block that holds the whole active box is one homogeneous block over vacuum: named, with the
// bound a block must stay under (the front ends refuse it); a block thicker than the cloth along
// an axis is noted, with the density fraction an edge block keeps.
TEST(Fit, ABlockThatHoldsTheWholeClothIsNamedAThickOneNoted) {
  Grid g(0.1);
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 12; ++j)
      for (int k = 0; k < 5; ++k) g.set_value(i + 3, j - 7, k + 100, 0.5F);  // anywhere in index space
  EXPECT_FALSE(whole_box_block(19, g).has_value());
  const auto whole = whole_box_block(20, g);
  ASSERT_TRUE(whole.has_value());
  EXPECT_EQ(whole->below, 20);
  EXPECT_NE(whole->text.find("holds the whole active box of grid 'density' (20x12x5 voxels)"), std::string::npos)
      << whole->text;
  EXPECT_EQ(thick_block_note(5, g), "");
  const std::string note = thick_block_note(8, g);
  EXPECT_NE(note.find("thicker than the cloth along z (5 voxels there)"), std::string::npos) << note;
  EXPECT_NE(note.find("at 0.62 of its density"), std::string::npos) << note;
  EXPECT_NE(thick_block_note(16, g).find("along yz (5 voxels there)"), std::string::npos);
  EXPECT_FALSE(whole_box_block(4096, Grid(0.1)).has_value());  // an empty grid: refused where it is used
}

TEST(Fit, LocalFieldsOfAKnownBlock) {
  // A 2³ block: x = 0 half holds a, x = 1 half holds b. Columns along x all have mean (a+b)/2;
  // along y and z the columns split by x: variance ((a−b)/2)².
  Grid g(0.5);
  const float a = 0.25f;
  const float b = 0.75f;
  for (int j = 0; j < 2; ++j) {
    for (int k = 0; k < 2; ++k) {
      g.set_value(0, j, k, a);
      g.set_value(1, j, k, b);
    }
  }
  const LocalFields f = local_fields(g, 2);
  EXPECT_EQ(f.blocks, 1U);
  EXPECT_DOUBLE_EQ(f.mean.voxel_size(), 1.0);
  EXPECT_NEAR(f.mean.value(0, 0, 0), 0.5, 1e-7);
  EXPECT_EQ(f.variance[0].value(0, 0, 0), 0.0f);
  EXPECT_TRUE(std::isinf(f.alpha[0].value(0, 0, 0)));
  EXPECT_NEAR(f.variance[1].value(0, 0, 0), 0.0625, 1e-7);
  EXPECT_NEAR(f.variance[2].value(0, 0, 0), 0.0625, 1e-7);
  EXPECT_NEAR(f.alpha[1].value(0, 0, 0), 0.25 / 0.0625, 1e-5);
  EXPECT_NEAR(f.beta[2].value(0, 0, 0), 0.5 / 0.0625, 1e-5);
  // The coarse grid covers the same world box as its fine block.
  EXPECT_EQ(f.mean.origin(), g.origin());
  const auto path = std::filesystem::temp_directory_path() / "weft_fit_local_fields_test.vdb";
  save_local_fields(f, path, FieldChannels::all);
  const Grid back = Grid::load(path, "alpha_y");
  EXPECT_NEAR(back.value(0, 0, 0), 4.0, 1e-5);
  // The variances are stored as half floats, α and β as floats.
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_TRUE(f.variance[a].stored_as_half());
    EXPECT_FALSE(f.alpha[a].stored_as_half());
  }
  for (const volume::GridCount& c : volume::count_grids(path))
    EXPECT_EQ(c.value_bytes, c.name.starts_with("var_") ? 2 : 4) << c.name;
  // The render file holds exactly the four grids the local-gamma medium reads.
  save_local_fields(f, path, FieldChannels::render);
  std::vector<std::string> names;
  for (const volume::GridCount& c : volume::count_grids(path)) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"mean_concentration", "var_concentration_x", "var_concentration_y",
                                             "var_concentration_z"}));
  EXPECT_THROW((void)Grid::load(path, "alpha_y"), Error);
  std::filesystem::remove(path);
  EXPECT_THROW((void)local_fields(g, 0), Error);
}

TEST(Fit, LocalFieldsKeepFloatVariancesBeyondHalfsRange) {
  // An extinction grid in large length units (2000 per unit in every other x slice): the y and z
  // columns' means are 0 or 2000, a variance of 10⁶ per block, beyond half's 65504. The fields
  // keep every variance as a float (not +∞), exactly, and α, β follow from them; scaled down by
  // 100 the same grid's variances (100) fit and are stored as half.
  for (const float value : {2000.0F, 20.0F}) {
    Grid g(0.01);
    for (int i = 0; i < 16; i += 2) {
      for (int j = 0; j < 16; ++j) {
        for (int k = 0; k < 16; ++k) g.set_value(i, j, k, value);
      }
    }
    const LocalFields f = local_fields(g, 8);
    const double v = 0.25 * value * value;
    const bool half = v <= volume::kHalfMax;
    SCOPED_TRACE(testing::Message() << "value " << value);
    for (std::size_t a = 0; a < 3; ++a) EXPECT_EQ(f.variance[a].stored_as_half(), half);
    EXPECT_EQ(f.variance[0].value(0, 0, 0), 0.0F);
    EXPECT_EQ(f.variance[1].value(0, 0, 0), static_cast<float>(v));
    EXPECT_EQ(f.variance[2].value(1, 1, 0), static_cast<float>(v));
    EXPECT_NEAR(f.alpha[1].value(0, 0, 0), 0.25 * value * value / v, 1e-6);  // C̄²/V = 1
  }
}

// Reference local statistics of the block at `key`, straight from the definition (a dense loop
// over the block's B³ voxels: for small test grids only).
struct Reference {
  double mean = 0.0;
  std::array<double, 3> variance{};
};
// Block `key` of side B anchored at the active box's lower corner (volume/block_lattice.h).
Reference reference_block(const Grid& g, int B, std::array<int, 3> key) {
  const std::array<int, 3> a = g.active_bbox().min;
  Reference r;
  const double n = static_cast<double>(B) * B * B;
  std::array<std::vector<double>, 3> cols;
  for (auto& c : cols) c.assign(static_cast<std::size_t>(B) * B, 0.0);
  for (int i = 0; i < B; ++i) {
    for (int j = 0; j < B; ++j) {
      for (int k = 0; k < B; ++k) {
        const double v = g.value(a[0] + key[0] * B + i, a[1] + key[1] * B + j, a[2] + key[2] * B + k);
        r.mean += v / n;
        cols[0][static_cast<std::size_t>(j * B + k)] += v / B;
        cols[1][static_cast<std::size_t>(i * B + k)] += v / B;
        cols[2][static_cast<std::size_t>(i * B + j)] += v / B;
      }
    }
  }
  for (std::size_t a = 0; a < 3; ++a) {
    double s2 = 0.0;
    for (const double c : cols[a]) s2 += (c - r.mean) * (c - r.mean);
    r.variance[a] = s2 / static_cast<double>(cols[a].size());
  }
  return r;
}

TEST(Fit, LocalFieldsDenseAndSparseBlocksMatchTheDefinition) {
  // A scatter of voxels over [−20, 40)³: blocks of 7 (dense columns, several blocks) and of 70
  // (sparse columns; one block holds the data) against the dense definition, blocks anchored at
  // the active box's lower corner.
  Grid g(0.1);
  for (int n = 0; n < 4000; ++n) {
    const int i = (n * 37) % 60 - 20;
    const int j = (n * 53) % 60 - 20;
    const int k = (n * 71 + n / 7) % 60 - 20;
    g.set_value(i, j, k, 0.05f + 0.9f * static_cast<float>((n * 29) % 100) / 100.0f);
  }
  for (const int B : {7, 70}) {
    const LocalFields f = local_fields(g, B);
    EXPECT_GT(f.blocks, 0U);
    const std::array<int, 3> anchor = g.active_bbox().min;
    for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(f.mean.origin()[a], g.origin()[a] + 0.1 * anchor[a], 1e-12);
    // The blocks of a few of the voxels.
    for (const int n : {0, 1, 2, 7, 100, 2001}) {
      const std::array<int, 3> voxel{(n * 37) % 60 - 20, (n * 53) % 60 - 20, (n * 71 + n / 7) % 60 - 20};
      std::array<int, 3> key{};
      for (std::size_t a = 0; a < 3; ++a)
        key[a] = static_cast<int>(std::floor(static_cast<double>(voxel[a] - anchor[a]) / B));
      const Reference r = reference_block(g, B, key);
      SCOPED_TRACE(testing::Message() << "B = " << B << ", block " << key[0] << "," << key[1] << "," << key[2]);
      ASSERT_GT(r.mean, 0.0);
      EXPECT_NEAR(f.mean.value(key[0], key[1], key[2]), r.mean, 1e-6 * r.mean);
      for (std::size_t a = 0; a < 3; ++a) {
        // Stored as half: within its rounding (2⁻¹¹ relative, 2⁻²⁵ absolute below 2⁻¹⁴).
        EXPECT_NEAR(f.variance[a].value(key[0], key[1], key[2]), r.variance[a],
                    std::ldexp(r.variance[a], -11) + 1e-5 * r.variance[a] + 3e-8);
      }
    }
  }
}

TEST(Fit, LocalFieldsDoNotMoveWithTheIndexOrigin) {
  // The same voxels at other index origins (shifts that are not multiples of the block) with the
  // origin moved back: blocks anchored to the cloth (volume/block_lattice.h) give the same
  // fields at the same coarse indices and world positions, to float rounding of the sums.
  Grid g(0.1);
  for (int n = 0; n < 3000; ++n) {
    g.set_value((n * 37) % 45 - 20, (n * 53) % 41 - 10, (n * 71 + n / 7) % 23, 0.05f + 0.009f * ((n * 29) % 100));
  }
  const int B = 6;
  const LocalFields f = local_fields(g, B);
  for (const std::array<int, 3> shift : {std::array<int, 3>{1, 0, 0}, {0, 5, 2}, {-7, -3, -1}, {1001, -513, 37}}) {
    Grid moved(g.voxel_size());
    std::array<double, 3> o = g.origin();
    for (std::size_t a = 0; a < 3; ++a) o[a] -= shift[a] * g.voxel_size();
    moved.set_origin(o);
    const auto box = g.active_bbox();
    for (int i = box.min[0]; i <= box.max[0]; ++i)
      for (int j = box.min[1]; j <= box.max[1]; ++j)
        for (int k = box.min[2]; k <= box.max[2]; ++k)
          if (const float v = g.value(i, j, k); v > 0.0F) moved.set_value(i + shift[0], j + shift[1], k + shift[2], v);
    const LocalFields m = local_fields(moved, B);
    SCOPED_TRACE(testing::Message() << "shift " << shift[0] << "," << shift[1] << "," << shift[2]);
    EXPECT_EQ(m.blocks, f.blocks);
    for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(m.mean.origin()[a], f.mean.origin()[a], 1e-9);
    const auto cb = f.mean.active_bbox();
    for (int i = cb.min[0]; i <= cb.max[0]; ++i) {
      for (int j = cb.min[1]; j <= cb.max[1]; ++j) {
        for (int k = cb.min[2]; k <= cb.max[2]; ++k) {
          const float mean = f.mean.value(i, j, k);
          EXPECT_NEAR(m.mean.value(i, j, k), mean, 1e-6F * mean);
          for (std::size_t a = 0; a < 3; ++a) {
            const float var = f.variance[a].value(i, j, k);
            // Both stored as half: float sums in another order may round to neighbouring halves.
            EXPECT_NEAR(m.variance[a].value(i, j, k), var, std::ldexp(var, -10) + 1e-9F);
          }
        }
      }
    }
  }
}

TEST(Fit, LocalFieldsOfAHugeBlockStayBounded) {
  // The largest block over a small grid: one block, memory bounded by the active voxels (the
  // estimate) instead of a dense 4096³ copy (256 GiB), and the statistics of that one block.
  Grid g(0.1);
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) g.set_value(i, j, (i * j) % 5, 0.5f);
  }
  const LocalFieldsEstimate e = estimate_local_fields(g, kMaxLocalBlock);
  EXPECT_LT(e.bytes, 64ULL << 20U);
  const LocalFields f = local_fields(g, kMaxLocalBlock);
  ASSERT_EQ(f.blocks, 1U);
  const double B = kMaxLocalBlock;
  const double total = 0.5 * 900;
  const double m = total / (B * B * B);
  EXPECT_NEAR(f.mean.value(0, 0, 0), m, 1e-6 * m);
  // z columns: 900 columns of one voxel each (mean 0.5/B), the rest empty.
  const double cz = 0.5 / B;
  const double var_z = (900 * (cz - m) * (cz - m) + (B * B - 900) * m * m) / (B * B);
  // Stored as half (fit/local_fields.h): 8·10⁻¹³ is below half's smallest subnormal, so 0. The
  // sparse columns' variance itself is checked against the definition at B = 70 above. A block
  // this empty (C̄ = 6.5·10⁻⁹: σC̄ ≈ 10⁻⁶ per length unit at σ = 100) attenuates nothing, so its
  // law does not matter (docs/render.md §5b "Storage").
  EXPECT_EQ(f.variance[2].value(0, 0, 0), volume::half_precision(static_cast<float>(var_z)));
  EXPECT_EQ(f.variance[2].value(0, 0, 0), 0.0F);
  EXPECT_THROW(check_local_block(kMaxLocalBlock + 1), Error);
  EXPECT_THROW(check_local_block(0), Error);
}

}  // namespace
}  // namespace weft::fit
