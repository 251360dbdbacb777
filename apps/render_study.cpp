// `weft render --study`: the files of the accuracy-vs-time study (docs/render.md §6c).
#include "render_study.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string_view>

#include <fmt/format.h>

#include "terminal_progress.h"
#include "weft/core/atomic_file.h"
#include "weft/dist/distributed.h"
#include "weft/study/albedo_fit.h"
#include "weft/study/render_study_report.h"
#include "weft/viz/chart.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;

fs::path beside(const fs::path& exr, const std::string& suffix) {
  fs::path p = exr;
  p.replace_extension(suffix);
  return p;
}

/// One colour per model, one marker per coarsening factor (the chart's legend names both).
viz::Rgb model_colour(const std::string& model) {
  if (model == "exponential") return {31, 119, 180};
  if (model == "local-gamma") return {214, 39, 40};
  if (model == "homogeneous gamma") return {44, 160, 44};
  if (model == "shadow-corrected") return {148, 103, 189};
  if (model == "albedo-corrected") return {255, 127, 14};
  return {0, 0, 0};  // the fine grid
}

viz::Marker factor_marker(int factor) {
  switch (factor) {
    case 2:
      return viz::Marker::circle;
    case 4:
      return viz::Marker::square;
    case 8:
      return viz::Marker::diamond;
    case 16:
      return viz::Marker::cross;
    default:
      return viz::Marker::plus;
  }
}

/// Left: RMSE vs seconds of every candidate on its way to the budget (log–log); the fine grid
/// falls as t^{-1/2}, a biased candidate levels off at its bias. Right: bias (solid) and noise
/// at equal time (dashed) against the coarsening factor per model; the fine grid at factor 1,
/// the slab as flat dotted lines.
}  // namespace

viz::RenderOutcome write_study_chart(const study::StudyResult& r, const fs::path& path, const std::string& label) {
  viz::Chart curves;
  curves.title = "RMSE against the reference vs render time";
  curves.x_label = "seconds";
  curves.y_label = "RMSE";
  curves.log_x = true;
  curves.log_y = true;
  curves.width = 760;
  curves.height = 600;
  for (const auto& c : r.candidates) {
    viz::Series s;
    s.label = c.name;
    for (const auto& p : c.curve) {
      s.x.push_back(p.seconds);
      s.y.push_back(p.rmse);
    }
    s.color = model_colour(c.model);
    s.style = c.model == "exponential" ? viz::LineStyle::dashed
              : c.factor == 0          ? viz::LineStyle::dotted
                                       : viz::LineStyle::solid;
    s.width = c.factor == 1 ? 3.0F : 2.0F;
    s.marker = c.factor <= 1 ? viz::Marker::circle : factor_marker(c.factor);
    curves.series.push_back(std::move(s));
  }
  viz::Chart split = curves;
  split.title = "bias (converged) and noise (at equal time) vs coarsening";
  split.x_label = "coarsening factor (fine grid = 1)";
  split.y_label = "RMSE";
  split.log_y = false;  // a bias estimate of 0 must stay on the chart
  split.series.clear();
  std::map<std::string, viz::Series> bias;
  std::map<std::string, viz::Series> noise;
  std::vector<double> factors;
  const study::StudyCandidate* slab = nullptr;
  for (const auto& c : r.candidates) {
    if (c.factor == 0) {
      slab = &c;
      continue;
    }
    factors.push_back(c.factor);
    const std::vector<std::string> models =
        c.factor == 1 ? std::vector<std::string>{"exponential", "local-gamma"} : std::vector<std::string>{c.model};
    for (const auto& m : models) {  // the fine grid starts both models' lines
      bias[m].x.push_back(c.factor);
      bias[m].y.push_back(c.bias);
      noise[m].x.push_back(c.factor);
      noise[m].y.push_back(c.noise);
    }
  }
  for (auto& [m, s] : bias) {
    s.label = m + " bias";
    s.color = model_colour(m);
    s.marker = viz::Marker::circle;
    split.series.push_back(s);
  }
  for (auto& [m, s] : noise) {
    s.label = m + " noise";
    s.color = model_colour(m);
    s.style = viz::LineStyle::dashed;
    s.marker = viz::Marker::square;
    split.series.push_back(s);
  }
  if (slab != nullptr && !factors.empty()) {
    const auto [lo, hi] = std::minmax_element(factors.begin(), factors.end());
    split.series.push_back(viz::Series{"slab bias",
                                       {*lo, *hi},
                                       {slab->bias, slab->bias},
                                       model_colour(slab->model),
                                       viz::LineStyle::dotted,
                                       2.0F,
                                       viz::Marker::none});
    split.series.push_back(viz::Series{"slab noise",
                                       {*lo, *hi},
                                       {slab->noise, slab->noise},
                                       model_colour(slab->model),
                                       viz::LineStyle::dash_dot,
                                       2.0F,
                                       viz::Marker::none});
  }
  return viz::save_chart_grid_png({curves, split}, 2, path, "Accuracy vs time: " + label);
}

void run_render_study(const render::SceneDesc& scene, study::StudySpec spec, const std::string& label,
                      const fs::path& exr, double exposure, const Context& ctx, WrittenFiles& files, bool fit_albedo) {
  spec.work_dir = beside(exr, ".study");
  spec.log = [&ctx](const std::string& line) { ctx.say(line); };
  // The albedo fit and the study both write here: a failure in either leaves nothing of them.
  FolderRollback outputs(spec.work_dir, dist::is_root());
  if (fit_albedo) {
    spec.albedo_factors = study::fit_albedo_factors(scene, spec, ctx.progress);
    std::vector<std::string> pairs;
    for (const auto& [f, k] : spec.albedo_factors) pairs.push_back(fmt::format("{}:{:.6g}", f, k));
    ctx.say(
        fmt::format("albedo factors fitted on this set-up (in-sample here; pass to other set-ups as "
                    "--study-albedo {})",
                    fmt::join(pairs, ",")));
  }
  // Say the cost before spending it: two images per candidate (the second at the first's spp).
  const std::size_t candidates = study::candidate_count(spec, spec.albedo_factors.size());
  if (spec.spp == 0)
    ctx.say(fmt::format("study: {} candidates x 2 images, about {} of rendering plus the reference at {} spp",
                        candidates, duration_text(2.0 * static_cast<double>(candidates) * spec.seconds),
                        spec.reference_spp));
  else
    ctx.say(fmt::format(
        "study: {} candidates x 2 images at {} spp plus the reference at {} spp ({:.3g} pixel samples in all)",
        candidates, spec.spp, spec.reference_spp,
        static_cast<double>(scene.camera.width) * scene.camera.height *
            (2.0 * static_cast<double>(candidates) * spec.spp + spec.reference_spp)));
  const study::StudyResult r = study::run_study(scene, spec, ctx.progress);
  if (!dist::is_root()) return;

  for (const auto& f : study::write_study_files(r, exr, spec.work_dir, exposure)) files.add(f.path, f.what);
  const fs::path chart = beside(exr, ".study.png");
  const viz::RenderOutcome outcome = write_study_chart(r, chart, label);
  if (outcome.written)
    files.add(chart, "RMSE vs time; bias and noise vs coarsening");
  else
    ctx.say(fmt::format("no chart {}: {}", chart.string(), outcome.reason));

  ctx.say(fmt::format("study ({}): reference {} spp in {:.3g} s", r.mode, r.reference.spp, r.reference_seconds));
  // The name column as wide as the longest name (local-gamma-optical-depth-4096x), so the
  // numbers stay under their headings.
  std::size_t name_width = std::string_view("candidate").size();
  for (const auto& c : r.candidates) name_width = std::max(name_width, c.name.size());
  ctx.say(fmt::format("{:<{}} {:>7} {:>9} {:>11} {:>11} {:>9} {:>11} {:>9} {:>13}", "candidate", name_width, "spp",
                      "seconds", "RMSE", "bias", "bias z", "noise", "speedup", "cloth bias %"));
  for (const auto& c : r.candidates)
    ctx.say(fmt::format("{:<{}} {:>7} {:>9.3g} {:>11.4g} {:>11.4g} {:>9.3g} {:>11.4g} {:>9.3g} {:>13.3g}", c.name,
                        name_width, c.spp, c.seconds, c.rmse, c.bias, c.bias_z(), c.noise, c.speedup,
                        r.cloth_mean > 0.0 ? 100.0 * c.cloth_bias / r.cloth_mean : 0.0));
  ctx.say(r.best_by_ground_truth_note);
  for (const auto& n : r.notes) ctx.say("note: " + n);
  ctx.say("headline: " + r.headline);
  outputs.keep();
}

}  // namespace weft::app
