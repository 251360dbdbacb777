// Moment matching (Eq. 19), the model and baseline laws, pooling and curve errors.
#include "weft/fit/gamma_moments.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "weft/core/error.h"
#include "weft/fit/window_stats.h"
#include "weft/transmittance/registry.h"
#include "weft/transmittance/shape_rate.h"

namespace weft::fit {

GammaFit gamma_from_moments(double mean, double variance, double sigma) {
  require_positive("gamma fit: sigma", sigma);
  require_non_negative("gamma fit: mean concentration", mean);
  require_non_negative("gamma fit: concentration variance", variance);
  GammaFit g;
  g.sigma = sigma;
  g.mean_concentration = mean;
  g.var_concentration = variance;
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (mean == 0.0) {
    // A vacuum: every sample is 0 (a non-negative variable with zero mean), T ≡ 1; so its
    // variance is 0, and a variance given with a zero mean describes no concentration at all.
    if (variance > 0.0)
      fail(
          "gamma fit: mean concentration 0 with variance {} is impossible (concentrations are >= 0, so a zero mean "
          "means every sample is 0 and the variance is 0)",
          variance);
    g.alpha = inf;
    g.beta = inf;
    return g;
  }
  if (variance == 0.0) {
    g.alpha = inf;  // S.46: Var C → 0 is the exponential law
    g.beta = inf;
    return g;
  }
  // β beyond the doubles is refused below; α beyond them is the exponential limit (α = ∞).
  const transmittance::ShapeRate s = transmittance::gamma_shape_rate(mean, variance);
  g.alpha = s.alpha;
  g.beta = s.beta;
  if (!(g.alpha > 0.0) || !std::isfinite(g.beta)) {
    fail("gamma fit: moments C = {}, Var C = {} give alpha = {}, beta = {}", mean, variance, g.alpha, g.beta);
  }
  return g;
}

transmittance::LawPtr model_law(const GammaFit& fit) {
  transmittance::LawSpec spec;
  if (fit.exponential() || fit.vacuum()) {
    spec.name = "exponential";
    spec.params = {{"mu", fit.mean_extinction()}};
  } else {
    spec.name = "gamma";
    spec.params = {{"mean_extinction", fit.mean_extinction()}, {"alpha", fit.alpha}};
  }
  return transmittance::make_law(spec);
}

transmittance::LawPtr exponential_law(const GammaFit& fit) {
  transmittance::LawSpec spec;
  spec.name = "exponential";
  spec.params = {{"mu", fit.mean_extinction()}};
  return transmittance::make_law(spec);
}

ConcentrationStats pool(const std::vector<ConcentrationStats>& per_axis) {
  if (per_axis.empty()) fail("isotropic statistics: no axes to pool");
  ConcentrationStats out;
  const auto n = static_cast<double>(per_axis.size());
  for (const auto& s : per_axis) {
    out.mean += s.mean / n;
    out.samples += s.samples;
    out.window += s.window / n;
  }
  for (const auto& s : per_axis) out.variance += (s.variance + (s.mean - out.mean) * (s.mean - out.mean)) / n;
  out.window_voxels = 0;  // a mix of axes
  return out;
}

std::vector<double> log_curve(const transmittance::Law& law, const std::vector<double>& depths) {
  std::vector<double> out(depths.size());
  for (std::size_t k = 0; k < depths.size(); ++k) out[k] = law.log_transmittance(depths[k]);
  return out;
}

CurveError compare(const volume::TransmittanceCurve& gt, const std::vector<double>& model_log_t) {
  if (model_log_t.size() != gt.size())
    fail("compare: model has {} depths, ground truth {}", model_log_t.size(), gt.size());
  CurveError e;
  double sum_t = 0.0;
  double sum_log = 0.0;
  double bias = 0.0;
  std::size_t below = 0;
  std::size_t positive = 0;
  const double log_floor = std::log(1e-6);
  for (std::size_t k = 0; k < gt.size(); ++k) {
    const double dt = std::abs(std::exp(model_log_t[k]) - gt.transmittance(k));
    e.max_abs_t = std::max(e.max_abs_t, dt);
    sum_t += dt * dt;
    if (gt.log_t[k] > log_floor) {
      const double dl = model_log_t[k] - gt.log_t[k];
      e.max_abs_log_t = std::max(e.max_abs_log_t, std::abs(dl));
      sum_log += dl * dl;
      bias += dl;
      ++e.log_points;
      if (gt.depth[k] > 0.0) {
        ++positive;
        if (dl < 0.0) ++below;
      }
    }
  }
  if (gt.size() > 0) e.rms_abs_t = std::sqrt(sum_t / static_cast<double>(gt.size()));
  if (e.log_points > 0) {
    e.rms_abs_log_t = std::sqrt(sum_log / static_cast<double>(e.log_points));
    e.mean_log_bias = bias / static_cast<double>(e.log_points);
  }
  if (positive > 0) e.below_fraction = static_cast<double>(below) / static_cast<double>(positive);
  return e;
}

}  // namespace weft::fit
