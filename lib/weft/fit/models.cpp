// Predictive models of axis beams from window statistics and local fields (fit/models.h).
#include "weft/fit/models.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/stage_clock.h"
#include "weft/fit/column_pass.h"
#include "weft/fit/local_models.h"
#include "weft/fit/node_kernels.h"
#include "weft/fit/window_stats.h"
#include "weft/transmittance/gamma_mixture.h"
#include "weft/transmittance/gap_gamma.h"
#include "weft/transmittance/registry.h"
#include "weft/transmittance/shape_rate.h"
#include "weft/volume/beam.h"
#include "weft/volume/columns.h"

namespace weft::fit {
namespace {

using detail::BlockStats;
using detail::kBins;
using detail::log_sum_exp_mean;
using detail::Memory;

/// The registry law of gamma_log_t: gamma (mean extinction σC̄, α = C̄²/Var), the exponential
/// when Var = 0.
transmittance::LawPtr gamma_or_exponential(double sigma, double mean, double var) {
  transmittance::LawSpec spec;
  if (mean > 0.0 && var > 0.0) {
    spec.name = "gamma";
    spec.params = {{"mean_extinction", sigma * mean}, {"alpha", transmittance::gamma_shape_rate(mean, var).alpha}};
  } else {
    spec.name = "exponential";
    spec.params = {{"mu", sigma * std::max(0.0, mean)}};
  }
  return transmittance::make_law(spec);
}
}  // namespace

namespace {

/// The window moments a pass gathered, as validate reports them (Eq. 19–20's C̄ and Var C).
ConcentrationStats window_moments_of(const detail::WindowSummary& ws, int w, double h) {
  ConcentrationStats s;
  s.mean = ws.moments.mean;
  s.variance = ws.moments.variance();
  s.samples = ws.moments.n;
  s.window_voxels = w;
  s.window = w * h;
  return s;
}

}  // namespace

ConcentrationStats window_moments(const volume::Grid& grid, int axis, double scale, ProgressSink& progress) {
  if (axis < 0 || axis > 2) fail("window moments: axis must be 0, 1 or 2, got {}", axis);
  if (grid.active_voxel_count() == 0) fail("window moments: grid '{}' has no active voxels", grid.name());
  const volume::ColumnReader reader(grid, axis);
  const int n = static_cast<int>(reader.box().extent()[static_cast<std::size_t>(axis)]);
  const int w = window_voxels(scale, grid.voxel_size(), n);
  const detail::ColumnPass pass = detail::column_pass(reader, false, w, {true, false, false}, progress);
  return window_moments_of(pass.windows, w, grid.voxel_size());
}

double gamma_log_t(double sigma, double mean, double var, double t) {
  if (!(mean > 0.0) || t == 0.0) return 0.0;
  if (!(var > 0.0)) return -sigma * mean * t;
  const auto [alpha, beta] = transmittance::gamma_shape_rate(mean, var);
  return -alpha * std::log1p(sigma * t / beta);
}

std::vector<PredictedModel> predict_axis(const volume::Grid& grid, const PredictionSpec& spec,
                                         const std::vector<double>& depths, ProgressSink& progress,
                                         ConcentrationStats* moments_out, PredictionCost* cost) {
  require_positive("predict: sigma", spec.sigma);
  if (!std::isfinite(spec.scale) || spec.scale < 0.0) fail("predict: scale must be >= 0, got {}", spec.scale);
  const int axis = volume::beam_axis(spec.direction);
  if (axis < 0) fail("predict: beam {} is not along an axis", volume::direction_label(spec.direction));
  if (grid.active_voxel_count() == 0) fail("predict: grid '{}' has no active voxels", grid.name());
  const bool reverse = spec.direction[static_cast<std::size_t>(axis)] < 0.0;
  const double h = grid.voxel_size();
  const volume::ColumnReader reader(grid, axis);
  const auto box = reader.box();
  const int n = static_cast<int>(box.extent()[static_cast<std::size_t>(axis)]);
  const int w = window_voxels(spec.scale, h, n);
  const double sigma = spec.sigma;
  // One pass over the columns gives the windows of every model and the blocks of the local ones.
  StageClock clock;
  const ModelSelection& models = spec.models;
  // Only the prediction reads the depth profile inside the blocks (fit/local_models.h).
  const detail::ColumnPass pass = detail::column_pass(
      reader, reverse, w, {models.needs_windows(), models.needs_blocks(), models.wants(kPredictedModel)}, progress);
  if (cost != nullptr) clock.lap(cost->statistics_seconds, cost->statistics_cpu_seconds);
  const detail::WindowSummary& ws = pass.windows;
  if (moments_out != nullptr) {
    *moments_out = ConcentrationStats{};
    if (models.needs_windows()) *moments_out = window_moments_of(ws, w, h);
    moments_out->window_voxels = w;
    moments_out->window = w * h;
  }
  std::vector<PredictedModel> out;
  auto add = [&](std::string name, std::string description, std::vector<std::pair<std::string, double>> params,
                 auto&& log_t_of, transmittance::LawPtr law = nullptr) {
    PredictedModel m;
    m.law = std::move(law);
    m.name = std::move(name);
    m.description = std::move(description);
    m.parameters = std::move(params);
    m.log_t.reserve(depths.size());
    for (std::size_t d = 0; d < depths.size(); ++d) m.log_t.push_back(log_t_of(d, depths[d]));
    out.push_back(std::move(m));
  };
  const double L = w * h;
  // The paper's law (Eq. 19–20) from all windows.
  if (models.wants("gamma")) {
    const double mean = ws.all.mean();
    const double var = ws.all.var();
    add(
        "gamma", "Eq. 19-20: gamma concentration from all windows of length L",
        {{"window", L},
         {"mean_concentration", mean},
         {"var_concentration", var},
         {"alpha", transmittance::gamma_shape_rate(mean, var).alpha},
         {"beta", transmittance::gamma_shape_rate(mean, var).beta}},
        [&](std::size_t, double t) { return gamma_log_t(sigma, mean, var, t); },
        gamma_or_exponential(sigma, mean, var));
  }
  // Eq. 16 with the empirical distribution (histogram bins at their own mean).
  if (models.wants("empirical")) {
    const double total = ws.all.n;
    std::vector<double> c;
    std::vector<double> p;
    if (ws.zeros > 0.0) {
      c.push_back(0.0);
      p.push_back(ws.zeros / total);
    }
    for (int b = 0; b < kBins; ++b) {
      const double cnt = ws.bin_count[static_cast<std::size_t>(b)];
      if (cnt > 0.0) {
        c.push_back(ws.bin_sum[static_cast<std::size_t>(b)] / cnt);
        p.push_back(cnt / total);
      }
    }
    std::vector<double> logs(c.size());
    add("empirical", "Eq. 16: mean over all windows of length L of exp(-sigma C_w t)",
        {{"window", L},
         {"windows", total},
         {"empty_fraction", ws.zeros / total},
         {"bins", static_cast<double>(c.size())}},
        [&](std::size_t, double t) {
          for (std::size_t i = 0; i < c.size(); ++i) logs[i] = -sigma * c[i] * t;
          return log_sum_exp_mean(logs, p);
        });
  }
  // Gap-aware gamma: empty windows see nothing, the others a gamma law.
  if (models.wants("gap-gamma")) {
    const double f0 = ws.all.n > 0.0 ? ws.zeros / ws.all.n : 0.0;
    const double mean = ws.nonzero.mean();
    const double var = ws.nonzero.var();
    // The registry's gap-gamma law (one implementation of its stable log T); α = ∞ without variance.
    const std::shared_ptr<const transmittance::Law> gap_law =
        mean > 0.0 && f0 < 1.0 ? std::unique_ptr<transmittance::Law>(std::make_unique<transmittance::GapGamma>(
                                     f0, sigma * mean, transmittance::gamma_shape_rate(mean, var).alpha))
                               : std::unique_ptr<transmittance::Law>(std::make_unique<transmittance::GammaMixture>(
                                     std::vector<transmittance::GammaComponent>{{1.0, 0.0, INFINITY}}));
    add(
        "gap-gamma", "gap fraction f0 (empty windows of length L) plus a gamma law of the others",
        {{"window", L},
         {"gap_fraction", f0},
         {"mean_concentration", mean},
         {"var_concentration", var},
         {"alpha", transmittance::gamma_shape_rate(mean, var).alpha},
         {"beta", transmittance::gamma_shape_rate(mean, var).beta}},
        [&](std::size_t, double t) { return gap_law->log_transmittance(t); }, gap_law);
  }
  // Across the beam: a gamma law per transverse cell of side L, mixed by rays.
  if (models.wants("across-beam")) {
    // The registry's gamma-mixture law: one component per group, weight = its share of the rays.
    double rays = 0.0;
    for (const auto& [k, g] : ws.groups) rays += g.rays;
    std::vector<transmittance::GammaComponent> components;
    for (const auto& [k, g] : ws.groups) {
      const double m = g.windows.mean();
      const double v = g.windows.var();
      components.push_back(
          {g.rays / rays, sigma * m, m > 0.0 ? transmittance::gamma_shape_rate(m, v).alpha : INFINITY});
    }
    const auto mixture = std::make_shared<const transmittance::GammaMixture>(std::move(components));
    add(
        "across-beam", "gamma law per transverse cell of side L, T the ray-weighted mean (gamma-mixture)",
        {{"window", L}, {"cell", L}, {"groups", static_cast<double>(ws.groups.size())}},
        [&](std::size_t, double t) { return mixture->log_transmittance(t); }, mixture);
  }
  // Local fields of blocks L³ (the statistics `weft fit --block` writes for rendering), clipped
  // to the active box so that each block holds exactly the beam's columns that cross it.
  if (models.needs_blocks()) {
    const BlockStats& st = pass.blocks;
    double blocks = 0.0;
    for (const auto& b : st.sums) blocks += b.n > 0.0 && b.s > 0.0 ? 1.0 : 0.0;
    const std::vector<std::tuple<std::string, std::string, Memory>> kinds{
        {"local-exponential", "blocks of side L, exponential per block (a coarse grid without statistics)",
         Memory::none},
        {"local-gamma",
         "blocks of side L with C and Var of column means, gamma hazard with memory from the ray's entry",
         Memory::from_entry},
        {"local-gamma-renewal", "blocks of side L, gamma hazard with memory restarting at every block",
         Memory::per_block},
    };
    for (const auto& [name, description, memory] : kinds) {
      if (!models.wants(name)) continue;
      auto curve = detail::block_field_curve(n, w, h, sigma, st, memory, depths);
      add(name, description, {{"block", L}, {"blocks", blocks}}, [&](std::size_t d, double) { return curve[d]; });
    }
    if (models.wants(kPredictedModel)) {
      auto curve = detail::two_scale_curve(n, w, h, sigma, st, depths);
      add(kPredictedModel,
          "blocks of side L; per ray a persistent gamma factor (its memory from the entry, variance from the measured "
          "covariance of adjacent blocks) times an independent gamma factor per block (the prediction)",
          {{"block", L}, {"blocks", blocks}}, [&](std::size_t d, double) { return curve[d]; });
    }
  }
  if (cost != nullptr) clock.lap(cost->models_seconds, cost->models_cpu_seconds);
  return out;
}

}  // namespace weft::fit
