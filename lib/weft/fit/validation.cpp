#include "weft/fit/validation.h"

#include <chrono>
#include <cmath>
#include <set>
#include <sstream>

#include "weft/core/error.h"

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
  const bool correlation_window = spec.window == ValidationSpec::kCorrelationWindow;
  if (!correlation_window && (!(spec.window >= 0.0) || !std::isfinite(spec.window))) {
    fail("validate: window must be >= 0, got {}", spec.window);
  }
  if (spec.directions.empty()) fail("validate: no beam directions");
  if (grid.active_voxel_count() == 0) fail("validate: grid '{}' has no active voxels", grid.name());
  for (const auto& d : spec.directions) {
    if (volume::beam_axis(d) < 0) fail("validate: beam {} is not along an axis", volume::direction_label(d));
  }
  Validation v;
  v.sigma = spec.sigma;
  v.voxel_size = grid.voxel_size();
  v.box = grid.active_bbox();
  v.active_voxels = grid.active_voxel_count();
  const auto ext = v.box.extent();
  v.mean_concentration =
      grid.sum() / (static_cast<double>(ext[0]) * static_cast<double>(ext[1]) * static_cast<double>(ext[2]));
  v.exponential = gamma_from_moments(v.mean_concentration, 0.0, spec.sigma);
  const auto exp_law = exponential_law(v.exponential);

  // Window statistics per axis (sense does not matter); all three when isotropic is asked.
  std::array<ConcentrationStats, 3> stats{};
  std::array<double, 3> stats_seconds{};
  std::array<bool, 3> have{};
  std::array<double, 3> corr{};
  auto stats_for = [&](int axis) {
    if (have[static_cast<std::size_t>(axis)]) return;
    const auto t0 = std::chrono::steady_clock::now();
    double window = spec.window;
    if (correlation_window) {
      corr[static_cast<std::size_t>(axis)] = correlation_length(grid, axis, progress);
      window = corr[static_cast<std::size_t>(axis)];
    }
    stats[static_cast<std::size_t>(axis)] = window_stats(grid, axis, window, progress);
    stats_seconds[static_cast<std::size_t>(axis)] = seconds_since(t0);
    have[static_cast<std::size_t>(axis)] = true;
  };
  if (spec.isotropic) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int a = 0; a < 3; ++a) stats_for(a);
    v.has_isotropic = true;
    v.isotropic_stats = pool({stats[0], stats[1], stats[2]});
    v.isotropic_fit = gamma_from_moments(v.isotropic_stats.mean, v.isotropic_stats.variance, spec.sigma);
    v.isotropic_seconds = seconds_since(t0);
  }
  const auto iso_law = spec.isotropic ? model_law(v.isotropic_fit) : nullptr;

  for (const auto& d : spec.directions) {
    AxisValidation av;
    av.direction = d;
    av.label = volume::direction_label(d);
    const int axis = volume::beam_axis(d);
    volume::BeamSpec beam;
    beam.direction = d;
    beam.scale = spec.sigma;
    beam.rays_per_column = spec.rays_per_column;
    beam.seed = spec.seed;
    beam.method = spec.method;
    auto t0 = std::chrono::steady_clock::now();
    av.ground_truth = volume::measure_beam(grid, beam, progress);
    av.beam_seconds = seconds_since(t0);
    stats_for(axis);
    av.stats = stats[static_cast<std::size_t>(axis)];
    av.correlation_length = corr[static_cast<std::size_t>(axis)];
    av.stats_seconds = stats_seconds[static_cast<std::size_t>(axis)];
    t0 = std::chrono::steady_clock::now();
    av.moment_fit = gamma_from_moments(av.stats.mean, av.stats.variance, spec.sigma);
    const auto& depth = av.ground_truth.depth;
    auto add_model = [&](const std::string& name, std::vector<double> log_t) {
      ModelCurve m;
      m.name = name;
      m.error = compare(av.ground_truth, log_t);
      m.log_t = std::move(log_t);
      av.models.push_back(std::move(m));
    };
    add_model("gamma", log_curve(*model_law(av.moment_fit), depth));
    if (spec.least_squares) {
      av.lsq_fit = fit_gamma_to_curve(av.ground_truth, spec.sigma, av.moment_fit);
      add_model("least-squares", log_curve(*model_law(av.lsq_fit.fit), depth));
    }
    if (iso_law) add_model("isotropic", log_curve(*iso_law, depth));
    add_model("exponential", log_curve(*exp_law, depth));
    av.fit_seconds = seconds_since(t0);
    v.axes.push_back(std::move(av));
  }
  return v;
}

}  // namespace weft::fit
