#include "weft/fit/validation.h"

#include <chrono>
#include <cmath>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/core/stage_clock.h"

namespace weft::fit {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

const ModelCurve& AxisValidation::model(const std::string& name) const {
  for (const auto& m : models) {
    if (m.name == name) return m;
  }
  fail("validation: axis {} has no model '{}'", label, name);
}

std::vector<std::array<double, 3>> parse_axes(const std::string& text) {
  std::vector<std::array<double, 3>> out;
  std::set<std::string> seen;
  std::istringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    if (part.empty()) fail("axes '{}': empty entry", text);
    const std::string name = (part[0] == '+' || part[0] == '-') ? part.substr(1) : part;
    if (name != "x" && name != "y" && name != "z") {
      fail("axes '{}': '{}' is not x, y or z (optionally signed)", text, part);
    }
    const auto d = volume::parse_direction(part);
    if (volume::beam_axis(d) < 0) fail("axes '{}': '{}' is not x, y or z (optionally signed)", text, part);
    const std::string label = volume::direction_label(d);
    if (!seen.insert(label).second) fail("axes '{}': '{}' given twice", text, part);
    out.push_back(d);
  }
  if (out.empty()) fail("axes '{}': no axis given", text);
  return out;
}

Validation validate(const volume::Grid& grid, const ValidationSpec& spec, ProgressSink& progress) {
  require_positive("validate: sigma", spec.sigma);
  for (double L : spec.scale) {
    if (!std::isfinite(L) || L < 0.0) fail("validate: scale must be >= 0, got {}", L);
  }
  if (spec.directions.empty()) fail("validate: no beam directions");
  if (grid.active_voxel_count() == 0) fail("validate: grid '{}' has no active voxels", grid.name());
  for (const auto& d : spec.directions) {
    if (volume::beam_axis(d) < 0) fail("validate: beam {} is not along an axis", volume::direction_label(d));
  }
  Validation v;
  v.models = spec.models;
  v.sigma = spec.sigma;
  v.voxel_size = grid.voxel_size();
  v.box = grid.active_bbox();
  v.active_voxels = grid.active_voxel_count();
  const auto ext = v.box.extent();
  v.mean_concentration =
      grid.sum() / (static_cast<double>(ext[0]) * static_cast<double>(ext[1]) * static_cast<double>(ext[2]));
  v.exponential = gamma_from_moments(v.mean_concentration, 0.0, spec.sigma);
  const auto exp_law = exponential_law(v.exponential);

  // Window statistics per axis at its scale (sense does not matter), when a model computed needs
  // them; all three for isotropic. The predictive models of a beam are computed first, from the
  // voxels alone, and their pass over the columns gives the axis's window statistics too (one
  // read of the voxels per beam); window_moments reads an axis only when no beam's models did.
  const ModelSelection& chosen = spec.models;
  const bool axis_models = chosen.any_axis_model();
  const bool windows = chosen.needs_windows();
  std::array<ConcentrationStats, 3> stats{};
  std::array<double, 3> stats_seconds{};
  std::array<double, 3> stats_cpu_seconds{};
  std::array<bool, 3> have{};
  std::vector<std::vector<PredictedModel>> predictions(spec.directions.size());
  std::vector<PredictionCost> prediction_cost(spec.directions.size());
  std::vector<std::vector<double>> beam_depths(spec.directions.size());
  auto beam_spec = [&](const std::array<double, 3>& d) {
    volume::BeamSpec beam;
    beam.direction = d;
    beam.scale = spec.sigma;
    beam.rays_per_column = spec.rays_per_column;
    beam.seed = spec.seed;
    beam.method = spec.method;
    return beam;
  };
  std::vector<double> window_length(spec.directions.size(), 0.0);
  if (axis_models) {
    for (std::size_t i = 0; i < spec.directions.size(); ++i) {
      const auto& d = spec.directions[i];
      const auto a = static_cast<std::size_t>(volume::beam_axis(d));
      // The depths of the beam follow from the grid alone (one voxel apart from the entry face).
      beam_depths[i] = volume::beam_depths(grid, beam_spec(d));
      PredictionSpec ps;
      ps.direction = d;
      ps.sigma = spec.sigma;
      ps.scale = spec.scale[a];
      ps.models = chosen;
      ConcentrationStats moments;
      predictions[i] = predict_axis(grid, ps, beam_depths[i], progress, &moments, &prediction_cost[i]);
      window_length[i] = moments.window;
      if (windows && !have[a]) {
        stats[a] = moments;
        have[a] = true;
      }
    }
  }
  auto stats_for = [&](int axis) {
    const auto a = static_cast<std::size_t>(axis);
    if (have[a]) return;
    StageClock clock;
    // The column pass's windows, as a beam's models compute them: the same bits in any
    // selection of models (window_stats, a dense pass, differs in the last digits).
    stats[a] = window_moments(grid, axis, spec.scale[a], progress);
    clock.lap(stats_seconds[a], stats_cpu_seconds[a]);
    have[a] = true;
  };
  if (chosen.wants("isotropic")) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int a = 0; a < 3; ++a) stats_for(a);
    v.has_isotropic = true;
    v.isotropic_stats = pool({stats[0], stats[1], stats[2]});
    v.isotropic_fit = gamma_from_moments(v.isotropic_stats.mean, v.isotropic_stats.variance, spec.sigma);
    v.isotropic_seconds = seconds_since(t0);
  }
  const auto iso_law = chosen.wants("isotropic") ? model_law(v.isotropic_fit) : nullptr;

  for (std::size_t i = 0; i < spec.directions.size(); ++i) {
    const auto& d = spec.directions[i];
    AxisValidation av;
    av.direction = d;
    av.label = volume::direction_label(d);
    const int axis = volume::beam_axis(d);
    const auto a = static_cast<std::size_t>(axis);
    const volume::BeamSpec beam = beam_spec(d);
    const std::vector<double> depths = axis_models ? beam_depths[i] : volume::beam_depths(grid, beam);
    if (windows) {
      stats_for(axis);
      av.has_stats = true;
      av.stats = stats[a];
      av.scale = av.stats.window;
    } else {
      av.scale = window_length[i];  // the blocks' side: what the local models were built on
    }
    if (axis_models) {
      av.stats_seconds = prediction_cost[i].statistics_seconds;
      av.stats_cpu_seconds = prediction_cost[i].statistics_cpu_seconds;
    } else {
      av.stats_seconds = stats_seconds[a];
      av.stats_cpu_seconds = stats_cpu_seconds[a];
    }
    StageClock clock;
    if (av.has_stats) av.moment_fit = gamma_from_moments(av.stats.mean, av.stats.variance, spec.sigma);
    auto add_model = [&](ModelCurve m) { av.models.push_back(std::move(m)); };
    if (chosen.wants("gamma")) {
      ModelCurve m;
      m.name = "gamma";
      m.description = "Eq. 19-20 (the paper): gamma concentration from the window statistics";
      m.parameters = {{"window", av.stats.window},
                      {"mean_concentration", av.moment_fit.mean_concentration},
                      {"var_concentration", av.moment_fit.var_concentration},
                      {"alpha", av.moment_fit.alpha},
                      {"beta", av.moment_fit.beta}};
      m.law = model_law(av.moment_fit);
      m.log_t = log_curve(*m.law, depths);
      add_model(std::move(m));
    }
    if (axis_models) {
      for (auto& p : predictions[i]) {
        if (p.name == "gamma") continue;  // the same law as above (one row per model)
        ModelCurve m;
        m.name = p.name;
        m.description = p.description;
        m.parameters = std::move(p.parameters);
        m.log_t = std::move(p.log_t);
        m.law = std::move(p.law);
        add_model(std::move(m));
      }
    }
    if (iso_law) {
      ModelCurve m;
      m.name = "isotropic";
      m.description = "gamma law from the window statistics of all three axes pooled";
      m.parameters = {{"alpha", v.isotropic_fit.alpha}, {"beta", v.isotropic_fit.beta}};
      m.log_t = log_curve(*iso_law, depths);
      m.law = iso_law;
      add_model(std::move(m));
    }
    {
      ModelCurve m;
      m.name = "exponential";
      m.description = "Beer-Lambert with the box-mean extinction (the RTE baseline)";
      m.parameters = {{"mean_extinction", v.exponential.mean_extinction()}};
      m.log_t = log_curve(*exp_law, depths);
      m.law = exp_law;
      add_model(std::move(m));
    }
    clock.lap(av.fit_seconds, av.fit_cpu_seconds);
    av.fit_seconds += prediction_cost[i].models_seconds;
    av.fit_cpu_seconds += prediction_cost[i].models_cpu_seconds;
    // Only now the ground truth; every prediction above is already fixed.
    av.ground_truth = volume::measure_beam(grid, beam, progress);
    clock.lap(av.beam_seconds, av.beam_cpu_seconds);
    if (av.ground_truth.depth != depths) fail("validate: beam depths differ from the predicted depths (internal)");
    for (auto& m : av.models) m.error = compare(av.ground_truth, m.log_t);
    // The least-squares reference needs three depths for its two parameters and a residual; a
    // grid one voxel thick along this beam has two (t = 0 and its one voxel), so the reference
    // row is left out there and nothing else changes (it is never a prediction).
    // A fit that leaves the gamma family's range (α → 0 on a grid of a few voxels in a huge box:
    // Var C beyond a double) has no law to report; the reference row is left out with the reason,
    // and the predictions, which never depend on it, are reported as usual.
    bool fitted = false;
    if (chosen.wants("least-squares") && av.ground_truth.size() >= 3) {
      try {
        av.lsq_fit = fit_gamma_to_curve(av.ground_truth, spec.sigma, av.moment_fit);
        fitted = true;
      } catch (const Error& e) {
        av.lsq_fit = LeastSquaresFit{};
        av.least_squares_note = fmt::format("least-squares reference left out: {}", e.what());
      }
    }
    if (fitted) {
      ModelCurve m;
      m.name = "least-squares";
      m.description = "reference: the gamma law fitted to the ground truth (Levenberg-Marquardt); not a prediction";
      m.uses_ground_truth = true;
      m.parameters = {
          {"alpha", av.lsq_fit.fit.alpha}, {"beta", av.lsq_fit.fit.beta}, {"rms_residual_T", av.lsq_fit.rms}};
      m.log_t = log_curve(*model_law(av.lsq_fit.fit), depths);
      m.error = compare(av.ground_truth, m.log_t);
      av.models.push_back(std::move(m));
      double wall = 0.0;
      double cpu = 0.0;
      clock.lap(wall, cpu);
      av.fit_seconds += wall;
      av.fit_cpu_seconds += cpu;
    }
    v.axes.push_back(std::move(av));
  }
  return v;
}

}  // namespace weft::fit
