// The prediction (fit::kPredictedModel, docs/validate.md "The prediction"): its two limits are
// the renewal (nothing persists from block to block) and the memory from the entry (everything
// does), and validate reports it, never a model chosen with the ground truth.
#include <gtest/gtest.h>

#include <cmath>

#include "test_grids.h"
#include "weft/fit/models.h"
#include "weft/fit/report.h"
#include "weft/fit/validation.h"
#include "weft/volume/beam.h"

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

}  // namespace
}  // namespace weft::fit
