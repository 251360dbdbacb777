#include "weft/fit/report.h"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/fit/models.h"

namespace weft::fit {
namespace {

using json = nlohmann::json;

/// JSON cannot hold ∞ or NaN: such values are written as null.
json number_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json fit_json(const GammaFit& g) {
  return {{"mean_concentration", g.mean_concentration}, {"var_concentration", g.var_concentration},
          {"alpha", number_or_null(g.alpha)},           {"beta", number_or_null(g.beta)},
          {"mean_extinction", g.mean_extinction()},     {"exponential_limit", g.exponential()}};
}

json error_json(const CurveError& e) {
  return {{"max_abs_T", e.max_abs_t},          {"rms_abs_T", e.rms_abs_t},
          {"max_abs_logT", e.max_abs_log_t},   {"rms_abs_logT", e.rms_abs_log_t},
          {"mean_logT_bias", e.mean_log_bias}, {"fraction_below_ground_truth", e.below_fraction},
          {"logT_points", e.log_points}};
}

json stats_json(const ConcentrationStats& s) {
  return {{"mean", s.mean},
          {"variance", s.variance},
          {"samples", s.samples},
          {"window", s.window},
          {"window_voxels", s.window_voxels}};
}

}  // namespace

namespace {

/// An RMS error on T at or below this is the baseline being exact up to rounding (a uniform
/// grid: 3·10⁻¹⁶), far below any ground truth's own noise: a ratio to it would be rounding noise
/// over rounding noise.
constexpr double kExactRmsT = 1e-12;

bool baseline_exact(const AxisValidation& axis) { return !(axis.model("exponential").error.rms_abs_t > kExactRmsT); }

}  // namespace

std::vector<ModelRatio> model_ratios(const AxisValidation& axis) {
  const double e = axis.model("exponential").error.rms_abs_t;
  const bool exact = baseline_exact(axis);
  std::vector<ModelRatio> out;
  for (const auto& m : axis.models) {
    ModelRatio r;
    r.name = m.name;
    r.rms_abs_t = m.error.rms_abs_t;
    r.ratio = exact ? std::numeric_limits<double>::quiet_NaN() : m.error.rms_abs_t / e;
    r.uses_ground_truth = m.uses_ground_truth;
    out.push_back(r);
  }
  return out;
}

std::string ratios_undefined(const AxisValidation& axis) {
  if (!baseline_exact(axis)) return "";
  return fmt::format(
      "the exponential baseline is exact at this sigma or grid (its RMS error on T is {:.3g}, at most {:g}: rounding): "
      "no "
      "error to improve on, so a ratio to it is undefined",
      axis.model("exponential").error.rms_abs_t, kExactRmsT);
}

ModelRatio predicted(const AxisValidation& axis) {
  for (const auto& r : model_ratios(axis)) {
    if (r.name == kPredictedModel) return r;
  }
  fail("validation: axis {} has no prediction (model '{}')", axis.label, kPredictedModel);
}

ModelRatio best_by_ground_truth(const AxisValidation& axis) {
  ModelRatio best;
  best.rms_abs_t = std::numeric_limits<double>::infinity();
  for (const auto& r : model_ratios(axis)) {
    if (r.uses_ground_truth || r.name == "exponential") continue;
    if (r.rms_abs_t < best.rms_abs_t) best = r;
  }
  // ModelSelection::parse refuses a selection without a model to compare.
  if (best.name.empty()) fail("validation: axis {} has no model beside the baseline and references", axis.label);
  best.uses_ground_truth = true;  // the choice among the models is made with T_gt
  return best;
}

std::string validation_json(const Validation& v) {
  json j;
  j["sigma"] = v.sigma;
  j["voxel_size"] = v.voxel_size;
  j["active_voxels"] = v.active_voxels;
  j["mean_concentration_bbox"] = v.mean_concentration;
  j["exponential"] = fit_json(v.exponential);
  if (v.has_isotropic) j["isotropic"] = {{"stats", stats_json(v.isotropic_stats)}, {"fit", fit_json(v.isotropic_fit)}};
  j["models_computed"] = v.models.text();
  json axes = json::array();
  bool all_pass = true;
  int judged_axes = 0;    // axes whose prediction passes or fails
  int unjudged_axes = 0;  // axes with a prediction whose ratio is undefined
  for (const auto& a : v.axes) {
    json ax;
    ax["axis"] = a.label;
    ax["rays"] = a.ground_truth.rays;
    ax["method"] = a.ground_truth.method;
    ax["depth_max"] = a.ground_truth.depth.back();
    ax["scale"] = a.scale;
    // The window statistics and their gamma fit exist when a model computed needs them.
    ax["stats"] = a.has_stats ? stats_json(a.stats) : json(nullptr);
    ax["fits"] = json::object();
    if (a.has_stats) ax["fits"]["moment"] = fit_json(a.moment_fit);
    if (!a.least_squares_note.empty()) ax["least_squares_skipped"] = a.least_squares_note;
    if (a.lsq_fit.converged || a.lsq_fit.iterations > 0) {
      ax["fits"]["least_squares"] = fit_json(a.lsq_fit.fit);
      ax["fits"]["least_squares"]["rms_residual_T"] = a.lsq_fit.rms;
      ax["fits"]["least_squares"]["converged"] = a.lsq_fit.converged;
    }
    json models = json::object();
    json errors = json::object();
    for (const auto& m : a.models) {
      json params = json::object();
      for (const auto& [k, x] : m.parameters) params[k] = number_or_null(x);
      models[m.name] = {
          {"description", m.description}, {"uses_ground_truth", m.uses_ground_truth}, {"parameters", params}};
      errors[m.name] = error_json(m.error);
    }
    ax["models"] = models;
    ax["errors"] = errors;
    json ratios = json::object();
    for (const auto& r : model_ratios(a)) ratios[r.name] = number_or_null(r.ratio);
    ax["ratio_to_exponential_rms_T"] = ratios;
    const std::string undefined = ratios_undefined(a);
    ax["ratios_undefined"] = undefined.empty() ? json(nullptr) : json(undefined);
    const bool has_gamma = ratios.contains("gamma");  // before operator[] below, which would add the key
    const double paper = has_gamma && ratios["gamma"].is_number() ? ratios["gamma"].get<double>() : NAN;
    ax["gamma_over_exponential_rms_T"] = number_or_null(paper);
    const bool has_prediction = ratios.contains(kPredictedModel);
    if (has_prediction) {
      const auto p = predicted(a);
      ax["predicted"] = {{"model", p.name},
                         {"rms_abs_T", p.rms_abs_t},
                         {"ratio_to_exponential_rms_T", number_or_null(p.ratio)},
                         {"uses_ground_truth", false},
                         {"rule", kPredictionRule}};
    }
    const auto best = best_by_ground_truth(a);
    const json best_json = {{"model", best.name},
                            {"ratio_to_exponential_rms_T", number_or_null(best.ratio)},
                            {"uses_ground_truth", true},
                            {"note", "diagnostic: the model with the least error against the ground truth"}};
    ax["best_by_ground_truth"] = best_json;
    ax["best_predictive"] = best_json;  // the former key, same content
    const bool overestimates = a.model("exponential").error.mean_log_bias < 0.0;
    ax["exponential_overestimates_extinction"] = overestimates;
    // An acceptance is reported for a model computed whose ratio is defined (null otherwise: a
    // run without the prediction, or whose baseline is exact, neither passes nor fails it).
    const bool judged = has_prediction && undefined.empty();
    const bool pass = judged && predicted(a).ratio <= 1.0 / 3.0;
    ax["acceptance_predicted_at_most_third_of_exponential"] = judged ? json(pass) : json(nullptr);
    ax["acceptance_gamma_at_most_third_of_exponential"] =
        has_gamma && undefined.empty() ? json(paper <= 1.0 / 3.0) : json(nullptr);
    if (judged) {
      all_pass = all_pass && pass;
      ++judged_axes;
    } else if (has_prediction) {
      ++unjudged_axes;
    }
    ax["timings"] = {{"beam", a.beam_seconds},           {"stats", a.stats_seconds},
                     {"models", a.fit_seconds},          {"beam_cpu", a.beam_cpu_seconds},
                     {"stats_cpu", a.stats_cpu_seconds}, {"models_cpu", a.fit_cpu_seconds}};
    axes.push_back(ax);
  }
  j["axes"] = axes;
  // False once an axis fails; true only when every axis with the prediction was judged and passed.
  j["acceptance_all_axes"] =
      judged_axes > 0 && !all_pass ? json(false) : (judged_axes > 0 && unjudged_axes == 0 ? json(true) : json(nullptr));
  // The prediction's cost against the truth's, over every axis (docs/benchmarks.md "Validate:
  // predictions against the truth"): process CPU of every thread, and wall.
  double beams = 0.0, statistics = 0.0, models = 0.0, beams_wall = 0.0, statistics_wall = 0.0, models_wall = 0.0;
  for (const auto& a : v.axes) {
    beams += a.beam_cpu_seconds;
    statistics += a.stats_cpu_seconds;
    models += a.fit_cpu_seconds;
    beams_wall += a.beam_seconds;
    statistics_wall += a.stats_seconds;
    models_wall += a.fit_seconds;
  }
  j["cost_seconds"] = {{"beams_cpu", beams},
                       {"statistics_cpu", statistics},
                       {"models_cpu", models},
                       {"beams_wall", beams_wall},
                       {"statistics_wall", statistics_wall},
                       {"models_wall", models_wall},
                       {"predictions_over_beams_cpu", beams > 0.0 ? (statistics + models) / beams : 0.0}};
  return j.dump(2);
}

}  // namespace weft::fit
