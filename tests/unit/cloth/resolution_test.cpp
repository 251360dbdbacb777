// The predictions at the default scale are a property of the cloth, not of the voxel.
// The same cloth voxelized at 5, 10 and 20 µm: per axis, the predicted curves of the best
// predictive model (local-gamma) and of the paper's gamma law differ between resolutions by no
// more than the ground truth itself changes (plus twice the noise of that difference), and the
// scale L reported (provenance) agrees within 20 % (it is the same number).
#include <gtest/gtest.h>

#include <cmath>

#include "data_gen/cloth/cloth.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/volume/provenance.h"

namespace weft::cloth {
namespace {

struct Run {
  fit::Validation v;
  double scale = 0.0;
  double measured = 0.0;
};

Run run(const std::string& pattern, double h) {
  ClothSpec spec = default_cloth_spec();
  spec.pattern = pattern;
  spec.warp_count = 2;
  spec.weft_count = 2;
  spec.voxel_size = h;
  const ClothBuild b = build_cloth(spec, null_progress());
  const auto p = volume::read_provenance(b.grid);
  Run r;
  fit::ValidationSpec vs;
  vs.sigma = *p.sigma;
  const auto scale = fit::resolve_scale("yarn", b.grid, p);
  vs.scale = scale.length;
  vs.models = fit::ModelSelection::all().without("least-squares");
  r.v = fit::validate(b.grid, vs);
  r.scale = scale.length[0];
  r.measured = fit::measured_yarn_scale(b.grid);
  return r;
}

/// T of `a` at the depths of `b` (linear interpolation in depth), over their common range.
double rms_difference(const std::vector<double>& da, const std::vector<double>& ta, const std::vector<double>& db,
                      const std::vector<double>& tb) {
  double s = 0.0;
  int n = 0;
  std::size_t j = 0;
  for (std::size_t k = 0; k < db.size(); ++k) {
    if (db[k] > da.back()) break;
    while (j + 1 < da.size() && da[j + 1] < db[k]) ++j;
    const double f = j + 1 < da.size() ? (db[k] - da[j]) / (da[j + 1] - da[j]) : 0.0;
    const double t = j + 1 < da.size() ? ta[j] + f * (ta[j + 1] - ta[j]) : ta[j];
    s += (t - tb[k]) * (t - tb[k]);
    ++n;
  }
  return std::sqrt(s / std::max(n, 1));
}

std::vector<double> exp_of(const std::vector<double>& log_t) {
  std::vector<double> out;
  for (double l : log_t) out.push_back(std::exp(l));
  return out;
}

void check_pattern(const std::string& pattern) {
  const std::vector<double> hs{0.005, 0.01, 0.02};
  std::vector<Run> runs;
  for (double h : hs) runs.push_back(run(pattern, h));
  for (std::size_t i = 0; i + 1 < runs.size(); ++i) {
    const auto& fine = runs[i];
    const auto& coarse = runs[i + 1];
    EXPECT_NEAR(fine.scale, coarse.scale, 0.2 * coarse.scale) << pattern;
    // The voxel-estimated yarn scale (not a default) drifts with h: recorded, bounded only loosely.
    EXPECT_NEAR(fine.measured, coarse.measured, 0.45 * coarse.measured) << pattern << " measured yarn scale";
    for (std::size_t a = 0; a < fine.v.axes.size(); ++a) {
      const auto& fa = fine.v.axes[a];
      const auto& ca = coarse.v.axes[a];
      std::vector<double> tf;
      std::vector<double> tc;
      double noise = 0.0;
      for (std::size_t k = 0; k < fa.ground_truth.size(); ++k) tf.push_back(fa.ground_truth.transmittance(k));
      for (std::size_t k = 0; k < ca.ground_truth.size(); ++k) {
        tc.push_back(ca.ground_truth.transmittance(k));
        noise += ca.ground_truth.stderr_abs(k) * ca.ground_truth.stderr_abs(k);
      }
      // The fine beam's standard error is smaller; the coarse one bounds the difference's noise.
      noise = std::sqrt(2.0 * noise / static_cast<double>(tc.size()));
      const double gt_change = rms_difference(fa.ground_truth.depth, tf, ca.ground_truth.depth, tc);
      const double tolerance = gt_change + 2.0 * noise;
      for (const char* model : {"local-gamma", "gamma"}) {
        const double change = rms_difference(fa.ground_truth.depth, exp_of(fa.model(model).log_t),
                                             ca.ground_truth.depth, exp_of(ca.model(model).log_t));
        EXPECT_LE(change, tolerance) << pattern << " " << fa.label << " " << model << " between " << hs[i] << " and "
                                     << hs[i + 1] << " mm (ground truth changes by " << gt_change << ")";
      }
    }
  }
}

TEST(Resolution, PlainWeavePredictionsConvergeUnderRefinement) { check_pattern("plain"); }
TEST(Resolution, KnitPredictionsConvergeUnderRefinement) { check_pattern("stockinette"); }

}  // namespace
}  // namespace weft::cloth
