// The prediction (fit::kPredictedModel, docs/validate.md "The prediction"): its two limits are
// the renewal (nothing persists from block to block) and the memory from the entry (everything
// does), and validate reports it, never a model chosen with the ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "test_grids.h"
#include "weft/core/parallel.h"
#include "weft/fit/column_pass.h"
#include "weft/fit/models.h"
#include "weft/fit/node_kernels.h"
#include "weft/fit/report.h"
#include "weft/fit/validation.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/beam.h"
#include "weft/volume/dense.h"

namespace weft::fit {
namespace {

using volume::Grid;

const PredictedModel& find(const std::vector<PredictedModel>& ms, const std::string& name) {
  for (const auto& m : ms) {
    if (m.name == name) return m;
  }
  throw std::runtime_error("no model " + name);
}

std::vector<PredictedModel> predict_x(const Grid& g, double sigma, double L) {
  volume::BeamSpec b;
  b.direction = {1, 0, 0};
  PredictionSpec spec;
  spec.direction = {1, 0, 0};
  spec.sigma = sigma;
  spec.scale = L;
  return predict_axis(g, spec, volume::beam_depths(g, b));
}

TEST(Prediction, NothingPersistsIsTheRenewal) {
  // Blocks of 4 voxels along x; in even blocks the columns with even j are dense, in odd blocks
  // those with odd j: adjacent blocks' column means are anti-correlated, so no part persists.
  Grid g(1.0);
  g.set_origin({0, 0, 0});
  for (int i = 0; i < 16; ++i) {
    for (int j = 0; j < 4; ++j) {
      for (int k = 0; k < 4; ++k) g.set_value(i, j, k, ((i / 4) + j) % 2 == 0 ? 0.8f : 0.1f);
    }
  }
  const auto models = predict_x(g, 0.7, 4.0);
  const auto& p = find(models, kPredictedModel);
  const auto& r = find(models, "local-gamma-renewal");
  for (std::size_t k = 0; k < p.log_t.size(); ++k) EXPECT_NEAR(p.log_t[k], r.log_t[k], 1e-9) << "k " << k;
}

TEST(Prediction, EverythingPersistsIsTheMemoryFromTheEntry) {
  // Columns constant along x (C depends on j only): every block is the same and adjacent blocks
  // share all their variance, so the prediction is one gamma law per ray for the whole path,
  // the memory from the entry (local-gamma), up to its 32-node quadrature over P.
  Grid g(1.0);
  g.set_origin({0, 0, 0});
  for (int i = 0; i < 24; ++i) {
    for (int j = 0; j < 4; ++j) {
      for (int k = 0; k < 4; ++k) g.set_value(i, j, k, 0.1f + 0.25f * static_cast<float>(j));
    }
  }
  const auto models = predict_x(g, 0.5, 4.0);
  const auto& p = find(models, kPredictedModel);
  const auto& e = find(models, "local-gamma");
  const auto& r = find(models, "local-gamma-renewal");
  double gap_to_renewal = 0.0;
  for (std::size_t k = 0; k < p.log_t.size(); ++k) {
    EXPECT_NEAR(std::exp(p.log_t[k]), std::exp(e.log_t[k]), 0.01) << "k " << k;
    gap_to_renewal = std::max(gap_to_renewal, std::abs(std::exp(r.log_t[k]) - std::exp(e.log_t[k])));
  }
  EXPECT_GT(gap_to_renewal, 0.02);  // the two limits differ here (by 0.039 at t = 8): the test tells them apart
}

TEST(Prediction, ValidateReportsThePredictionAndLabelsTheBestAsChosenWithTheGroundTruth) {
  const Grid g = test::patterned_grid();
  const Validation v = test::validate_patterned(g);
  for (const auto& a : v.axes) {
    const ModelRatio p = predicted(a);
    EXPECT_EQ(p.name, kPredictedModel);
    EXPECT_FALSE(p.uses_ground_truth);
    EXPECT_EQ(p.rms_abs_t, a.model(kPredictedModel).error.rms_abs_t);
    const ModelRatio b = best_by_ground_truth(a);
    EXPECT_TRUE(b.uses_ground_truth);
    EXPECT_LE(b.rms_abs_t, p.rms_abs_t);
  }
  const std::string json = validation_json(v);
  EXPECT_NE(json.find("\"predicted\""), std::string::npos);
  EXPECT_NE(json.find("\"best_by_ground_truth\""), std::string::npos);
}

// A grid one voxel thick along a beam has two depths there (the entry face and its one voxel):
// the least-squares reference (two parameters and a residual) is left out of that axis only, and
// the predictions and the other axes are reported as usual.
TEST(Prediction, ASlabOneVoxelThickIsValidatedWithoutTheLeastSquaresRowAcrossIt) {
  constexpr int n = 12;
  std::vector<float> values(static_cast<std::size_t>(n) * n, 0.0f);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(0.1 + 0.8 * ((i * 37U) % 11U) / 10.0);
  Grid g(0.05);
  volume::from_dense(g, {0, 0, 0}, {n, n, 1}, values.data());
  ValidationSpec spec;
  spec.sigma = 4.0;
  spec.scale = {0.2, 0.2, 0.2};
  spec.directions = {{1, 0, 0}, {0, 0, 1}};
  const Validation v = validate(g, spec);
  ASSERT_EQ(v.axes.size(), 2U);
  const auto has_lsq = [](const AxisValidation& a) {
    for (const auto& m : a.models) {
      if (m.uses_ground_truth) return true;
    }
    return false;
  };
  EXPECT_TRUE(has_lsq(v.axes[0]));
  EXPECT_EQ(v.axes[1].ground_truth.size(), 2U);
  EXPECT_FALSE(has_lsq(v.axes[1]));
  EXPECT_TRUE(std::isfinite(v.axes[1].model(kPredictedModel).error.rms_abs_t));
  EXPECT_NE(validation_json(v).find("\"predicted\""), std::string::npos);
}

}  // namespace
}  // namespace weft::fit

namespace weft::fit {
namespace {

/// Yarn-like slabs with gaps, at a negative index origin: 30 to 120 face patches per axis (on
/// z more than the pass's 64 shards), columns that are empty, closed, or hold voxels far apart.
Grid gapped_grid() {
  constexpr int nx = 96, ny = 80, nz = 24;
  std::vector<float> values(static_cast<std::size_t>(nx) * ny * nz, 0.0f);
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      for (int k = 0; k < nz; ++k) {
        const unsigned hash = (static_cast<unsigned>(i) * 73856093U) ^ (static_cast<unsigned>(j) * 19349663U) ^
                              (static_cast<unsigned>(k) * 83492791U);
        const bool yarn = (i / 12 + j / 10 + k / 6) % 3 != 0;
        if (yarn && hash % 5 != 0)
          values[(static_cast<std::size_t>(i) * ny + j) * nz + k] = static_cast<float>(0.05 + (hash % 97) / 100.0);
      }
    }
  }
  Grid g(0.01);
  volume::from_dense(g, {-40, -30, -7}, {nx, ny, nz}, values.data());
  return g;
}

// The statistics pass is sharded over face patches and reduced in shard order (docs/validate.md):
// every model's curve and the window moments have the same bits for any thread count.
TEST(Prediction, StatisticsPassGivesTheSameBitsForAnyThreadCount) {
  const Grid g = gapped_grid();
  for (const auto& dir :
       {std::array<double, 3>{1, 0, 0}, std::array<double, 3>{0, -1, 0}, std::array<double, 3>{0, 0, -1}}) {
    volume::BeamSpec b;
    b.direction = dir;
    PredictionSpec spec;
    spec.direction = dir;
    spec.sigma = 30.0;
    spec.scale = 0.07;
    const auto depths = volume::beam_depths(g, b);
    std::vector<std::vector<PredictedModel>> runs;
    std::vector<ConcentrationStats> moments(3);
    for (unsigned threads : {1U, 2U, 3U}) {
      const ThreadLimit limit(threads);
      runs.push_back(predict_axis(g, spec, depths, null_progress(), &moments[runs.size()]));
    }
    for (std::size_t r = 1; r < runs.size(); ++r) {
      EXPECT_EQ(moments[r].mean, moments[0].mean);
      EXPECT_EQ(moments[r].variance, moments[0].variance);
      ASSERT_EQ(runs[r].size(), runs[0].size());
      for (std::size_t m = 0; m < runs[0].size(); ++m) {
        EXPECT_EQ(runs[r][m].parameters, runs[0][m].parameters) << runs[0][m].name;
        EXPECT_EQ(runs[r][m].log_t, runs[0][m].log_t) << runs[0][m].name;
      }
    }
    // The pass's window moments are the dense pass's (window_stats), up to rounding.
    const auto a = static_cast<int>(volume::beam_axis(dir));
    const ConcentrationStats dense = window_stats(g, a, spec.scale);
    EXPECT_EQ(moments[0].samples, dense.samples);
    EXPECT_NEAR(moments[0].mean, dense.mean, 1e-13 * dense.mean);
    EXPECT_NEAR(moments[0].variance, dense.variance, 1e-11 * dense.variance);
  }
}

// The depth profile inside a block (BlockStats::slices, docs/validate.md "The prediction"): a
// block whose concentration sits in its far half transmits everything until the beam reaches it,
// and at every block end the prediction is the uniform block's.
TEST(Prediction, TheProfileInsideABlockMovesItsHazardToWhereTheConcentrationIs) {
  constexpr int nx = 24, ny = 8, nz = 8, B = 6;
  Grid g(0.01);
  g.set_origin({0, 0, 0});
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      for (int k = 0; k < nz; ++k) {
        // In every block along x only its last 3 slices hold fibre, unevenly across the columns.
        if (i % B >= 3) g.set_value(i, j, k, static_cast<float>(0.1 + 0.1 * ((i + 2 * j + 3 * k) % 5)));
      }
    }
  }
  // The first slice of the grid must hold a voxel for the box to start at the entry face.
  g.set_value(0, 0, 0, 0.05f);
  const volume::ColumnReader reader(g, 0);
  volume::BeamSpec b;
  b.direction = {1, 0, 0};
  const auto depths = volume::beam_depths(g, b);
  const double sigma = 40.0;
  const double h = g.voxel_size();
  const auto with = detail::column_pass(reader, false, B, {false, true, true}, null_progress());
  const auto without = detail::column_pass(reader, false, B, {false, true, false}, null_progress());
  ASSERT_EQ(with.blocks.depth, nx);
  EXPECT_EQ(without.blocks.depth, 0);
  const auto profiled = detail::two_scale_curve(nx, B, h, sigma, with.blocks, depths);
  const auto uniform = detail::two_scale_curve(nx, B, h, sigma, without.blocks, depths);
  ASSERT_EQ(profiled.size(), depths.size());
  for (std::size_t d = 0; d < depths.size(); ++d) {
    const double slices = depths[d] / h;
    const auto k = static_cast<int>(std::lround(slices));
    if (k % B == 0) {
      EXPECT_NEAR(profiled[d], uniform[d], 1e-12 * (1.0 + std::abs(uniform[d]))) << "block end, depth " << k;
    } else if (k < 3) {
      // Only column (0, 0)'s first voxel before slice 3: nearly all of T is still there.
      EXPECT_GT(profiled[d], uniform[d]) << "depth " << k;
      EXPECT_GT(profiled[d], -0.05) << "depth " << k;
    }
  }
}

TEST(Prediction, ThePiecesBinIsTheHistogramsBin) {
  // bin_of_positive (the statistics pass, one per piece) reads the bin from the shifted bits;
  // bin_of takes exponent and mantissa apart: the same bin for every m > 0, at the octave edges,
  // below the first octave (subnormals included) and above the last.
  std::vector<double> ms{std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::min(),
                         std::numeric_limits<double>::max(), 1.0, 0.5};
  for (int e = detail::kMinExponent - 3; e <= detail::kMinExponent + detail::kOctaves + 3; ++e) {
    const double edge = std::ldexp(1.0, e);
    ms.insert(ms.end(), {edge, std::nextafter(edge, 0.0), std::nextafter(edge, 2.0 * edge)});
  }
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::uint64_t> bits(1, 0x7fefffffffffffffULL);  // every positive finite
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t b = bits(rng);
    double m = 0.0;
    std::memcpy(&m, &b, sizeof m);
    ms.push_back(m);
  }
  for (double m : ms) ASSERT_EQ(detail::bin_of_positive(m), detail::bin_of(m)) << m;
}

TEST(Prediction, NodeHazardsAreTheGammaCellIntegral) {
  // node_hazards is GammaCell::integral as a loop over nodes (vectorised: within a few ulp of
  // the scalar libm), including κ = 0 from v_b = 0 and from a node P = 0.
  const std::vector<double> p{0.0, 0.03, 0.2, 0.7, 1.0, 1.3, 2.9, 7.5, 31.0};
  std::vector<double> out(p.size());
  for (const double vb : {0.0, 1e-9, 0.05, 1.0, 40.0}) {
    for (const double s : {0.0, 0.02, 0.29}) {
      for (const double length : {0.02, 1e-7}) {
        const double sigma_mean = 106.1 * 0.37;
        detail::node_hazards(p.data(), p.size(), sigma_mean, vb, s, length, out.data());
        for (std::size_t j = 0; j < p.size(); ++j) {
          const double mu = sigma_mean * p[j];
          const transmittance::GammaCell cell{mu, vb > 0.0 ? mu * vb : 0.0, mu};
          const double want = cell.integral(s, length);
          EXPECT_NEAR(out[j], want, 8.0 * std::numeric_limits<double>::epsilon() * std::abs(want))
              << "vb " << vb << " s " << s << " length " << length << " node " << j;
        }
      }
    }
  }
}

TEST(Prediction, NegligibleNodesLeaveTheMeanBitForBit) {
  // Nodes kNegligibleHazard or more below the first cannot change the bits of the mean of
  // e^{at}: dropping them (two_scale_curve's `live`) gives exactly the mean over all nodes.
  std::vector<double> scratch(32);
  for (const double first : {0.0, -3.7, -812.5}) {
    std::vector<double> at(32);
    std::size_t live = 0;
    for (std::size_t j = 0; j < at.size(); ++j) {
      const double gap = 0.013 * static_cast<double>(j * j * j);  // increasing with the node
      at[j] = first - gap;
      if (gap <= detail::kNegligibleHazard) live = j + 1;
    }
    ASSERT_LT(live, at.size());
    const double all = detail::log_mean_exp_nodes(at.data(), at.size(), at.size(), scratch.data());
    EXPECT_EQ(detail::log_mean_exp_nodes(at.data(), live, at.size(), scratch.data()), all) << first;
    double direct = 0.0;  // the definition, in long double
    for (const double a : at) direct += std::exp(static_cast<long double>(a - first));
    EXPECT_NEAR(all, first + static_cast<double>(std::log(direct / 32.0L)), 1e-14 * (1.0 + std::abs(first)));
  }
}

}  // namespace
}  // namespace weft::fit
