#include "validate_corpus.h"

#include <chrono>
#include <filesystem>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "usage.h"
#include "validate_common.h"
#include "validate_output.h"
#include "weft/core/atomic_file.h"
#include "weft/dist/distributed.h"
#include "weft/dist/unit_store.h"
#include "weft/study/corpus.h"
#include "weft/viz/chart.h"
#include "weft/viz/display.h"
#include "written_files.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string corpus_csv(const std::vector<study::CorpusResult>& results) {
  std::string out =
      "case,pattern,preset,voxel_size_mm,axis,scale_mm,model,rms_abs_T,ratio_to_exponential,uses_ground_truth,"
      "predicted,voxel_minus_fibre_rms_T,fibre_stderr_rms_T\n";
  for (const auto& r : results) {
    for (const auto& a : r.axes) {
      for (const auto& m : a.models) {
        out += fmt::format("{},{},{},{:g},{},{:.6g},{},{},{},{},{},{},{}\n", r.c.name(), r.c.pattern, r.c.preset,
                           r.c.voxel_size, a.axis, a.scale, m.name, fmt_csv(m.rms_abs_t), fmt_csv(m.ratio),
                           m.uses_ground_truth ? "true" : "false", m.name == a.predicted.name ? "true" : "false",
                           fmt_csv(a.voxel_minus_fibre_rms), fmt_csv(a.fibre_stderr_rms));
      }
    }
  }
  return out;
}

/// Ratio to the exponential per case (x: case × axis index) and model; the 1/3 line dashed.
viz::Chart corpus_chart(const std::vector<study::CorpusResult>& results) {
  viz::Chart c;
  c.title = "corpus: RMS error on T over the exponential's, per case and axis (x, y, z)";
  c.x_label = "case x 3 + axis (order of corpus.csv)";
  c.y_label = "ratio to exponential";
  c.log_y = true;
  c.width = 1400;
  c.height = 800;
  std::vector<std::string> names;
  for (const auto& m : results.front().axes.front().models) names.push_back(m.name);
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == "exponential" || names[i] == "isotropic") continue;
    const auto st = model_style(names[i]);
    viz::Series s;
    s.label = names[i];
    s.color = st.color;
    s.style = viz::LineStyle::markers;
    s.marker = st.marker == viz::Marker::none ? viz::Marker::circle : st.marker;
    double x = 0.0;
    for (const auto& r : results) {
      for (const auto& a : r.axes) {
        s.x.push_back(x);
        s.y.push_back(a.models[i].ratio);
        x += 1.0;
      }
    }
    c.series.push_back(s);
  }
  viz::Series third;
  third.label = "1/3 (acceptance)";
  third.style = viz::LineStyle::dashed;
  third.color = {0, 0, 0};
  third.width = 1.5f;
  const double n = static_cast<double>(results.size() * results.front().axes.size());
  third.x = {-0.5, n - 0.5};
  third.y = {1.0 / 3.0, 1.0 / 3.0};
  c.series.push_back(third);
  return c;
}

}  // namespace

int run_corpus(const CorpusOptions& o, const Context& ctx) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto cases = as_usage([&] { return study::select_corpus_cases(study::corpus_cases(o.quick), o.cases); });
  const fs::path out = o.out;
  // Each finished case is recorded in <out>/units/ (rank 0), so a run that dies can be finished
  // with --resume; the key is everything a case's bytes depend on.
  json case_names = json::array();
  for (const auto& c : cases) case_names.push_back(c.name());
  const json key = {{"weft", "validate --corpus"}, {"cases", case_names}, {"seed", o.seed}, {"window", o.window}};
  dist::UnitStore store(out / "units", key.dump(2) + "\n", o.resume);
  if (dist::is_root()) ensure_directory(out);
  const std::vector<study::CorpusResult> results = study::run_corpus(cases, o.seed, o.window, ctx.progress, &store);
  if (!dist::is_root()) return 0;  // rank 0 gathered every case and writes
  WrittenFiles files;
  write_text_atomically(out / "corpus.csv", corpus_csv(results));
  files.add(out / "corpus.csv", "every case, axis and model");
  json cases_json = json::array();
  int misses = 0;
  double worst = 0.0;
  std::string worst_where;
  double worst_voxel = 0.0;
  for (const auto& r : results) {
    json axes = json::array();
    for (const auto& a : r.axes) {
      json models = json::object();
      for (const auto& m : a.models) models[m.name] = {{"rms_abs_T", m.rms_abs_t}, {"ratio", number_or_null(m.ratio)}};
      axes.push_back({{"axis", a.axis},
                      {"scale", a.scale},
                      {"predicted", a.predicted.name},
                      {"predicted_ratio", number_or_null(a.predicted.ratio)},
                      {"best_by_ground_truth", a.best.name},
                      {"best_predictive", a.best.name},  // the former key: chosen with the ground truth
                      {"best_ratio", number_or_null(a.best.ratio)},
                      {"best_uses_ground_truth", true},
                      {"voxel_minus_fibre",
                       {{"rms_T", a.voxel_minus_fibre_rms},
                        {"max_abs_T", a.voxel_minus_fibre_max},
                        {"rms_stderr_fibre", a.fibre_stderr_rms},
                        {"note", "voxel ground truth against the fibres' (opaque, same rays)"}}},
                      {"models", models}});
      worst_voxel = std::max(worst_voxel, a.voxel_minus_fibre_rms);
      if (!(a.predicted.ratio <= 1.0 / 3.0)) ++misses;
      if (!(a.predicted.ratio <= worst)) {
        worst = a.predicted.ratio;
        worst_where = fmt::format("{} {}", r.c.name(), a.axis);
      }
    }
    cases_json.push_back({{"case", r.c.name()},
                          {"sigma", r.sigma},
                          {"active_voxels", r.active_voxels},
                          {"seconds", r.seconds},
                          {"axes", axes}});
  }
  std::string plot = "skipped: --no-plot";
  if (!o.no_plot) {
    std::string why;
    if (!viz::ensure_display(&why)) {
      plot = fmt::format("not rendered: {}", why);
    } else {
      const auto pic = viz::save_chart_png(corpus_chart(results), out / "corpus.png");
      if (pic.written) {
        files.add(out / "corpus.png", "ratios per case and model");
        plot = "written";
      } else {
        plot = fmt::format("not rendered: {}", pic.reason);
      }
    }
  }
  json report = {{"weft", "validate --corpus"},
                 {"quick", o.quick},
                 {"case_filter", o.cases},
                 {"seed", o.seed},
                 {"window", o.window},
                 {"ranks", ctx.ranks()},
                 {"threads", ctx.threads()},
                 {"resumed_units", store.found()},
                 {"cases", cases_json},
                 {"axes_missing_one_third", misses},
                 {"worst_predicted_ratio", number_or_null(worst)},
                 {"worst_predicted_case", worst_where},
                 {"worst_voxel_minus_fibre_rms_T", worst_voxel},
                 {"corpus.png", plot},
                 {"seconds", seconds_since(t0)}};
  write_text_atomically(out / "corpus.json", report.dump(2) + "\n");
  files.add(out / "corpus.json", "summary");
  store.remove();  // the outputs are whole: the finished cases are no longer needed

  ctx.say(fmt::format(
      "weft validate --corpus: {} cases, sigma and scale L from each cloth's provenance; {} rank(s) x "
      "{} thread(s){}",
      cases.size(), ctx.ranks(), ctx.threads(),
      store.found() > 0 ? fmt::format("; {} case(s) resumed from {}", store.found(), store.folder().string())
                        : std::string()));
  ctx.say(fmt::format("{:<28} {:>4} {:>7} {:>7} {:>7} {:>9}   {:<20} {:>6} {:>9}", "case", "axis", "L mm", "gamma",
                      "local-g", "predicted", "best with T_gt", "ratio", "vox-fibre"));
  auto ratio_of = [](const study::CorpusAxis& a, const std::string& name) -> double {
    for (const auto& m : a.models) {
      if (m.name == name) return m.ratio;
    }
    return NAN;
  };
  for (const auto& r : results) {
    for (const auto& a : r.axes) {
      ctx.say(fmt::format("{:<28} {:>4} {:>7.3f} {:>7.3f} {:>7.3f} {:>9.3f}   {:<20} {:>6.3f} {:>9.4f}{}", r.c.name(),
                          a.axis, a.scale, ratio_of(a, "gamma"), ratio_of(a, "local-gamma"), a.predicted.ratio,
                          a.best.name, a.best.ratio, a.voxel_minus_fibre_rms,
                          a.predicted.ratio <= 1.0 / 3.0 ? "" : "  prediction misses 1/3"));
    }
  }
  ctx.say(fmt::format(
      "predicted ({}): {} of {} case axes miss 1/3 of the exponential's error; worst ratio {:.3f} ({}); {:.1f} s",
      results.front().axes.front().predicted.name, misses, results.size() * 3, worst, worst_where, seconds_since(t0)));
  ctx.say(
      fmt::format("voxel ground truth against the fibres' (vox-fibre, RMS of T_gt - T_fibre over depths): worst {:.4f}",
                  worst_voxel));
  files.say(ctx);
  return 0;
}

}  // namespace weft::app
