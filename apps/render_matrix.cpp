// `weft render --study` with no scene: the study matrix's files (docs/render.md §6e).
#include "render_matrix.h"

#include <algorithm>
#include <cstdlib>
#include <map>

#include <fmt/format.h>

#include "render_study.h"
#include "terminal_progress.h"
#include "usage.h"
#include "weft/core/atomic_file.h"
#include "weft/dist/distributed.h"
#include "weft/dist/unit_store.h"
#include "weft/render/cloth_scene.h"
#include "weft/study/render_matrix_report.h"
#include "weft/viz/chart.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;

/// One panel per cloth: the worst cloth bias over its set-ups (% of the mean cloth pixel) against
/// the coarsening factor, one line per model.
viz::RenderOutcome write_matrix_chart(const std::vector<study::MatrixHeadline>& headlines, const fs::path& path) {
  const std::vector<viz::Rgb> colours{{31, 119, 180}, {214, 39, 40}, {44, 160, 44},   {148, 103, 189},
                                      {255, 127, 14}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127}};
  std::vector<viz::Chart> panels;
  for (const auto& h : headlines) {
    viz::Chart c;
    c.title = h.cloth + ": worst cloth bias over light x view";
    c.x_label = "coarsening factor";
    c.y_label = "bias, % of the mean cloth pixel";
    c.log_x = true;
    c.width = 600;
    c.height = 480;
    std::map<std::string, viz::Series> by_model;
    for (const auto& v : h.verdicts) {
      if (v.factor < 2) continue;  // the slab has no factor
      viz::Series& s = by_model[v.model];
      s.x.push_back(v.factor);
      s.y.push_back(100.0 * v.worst_relative_bias);
    }
    std::size_t i = 0;
    for (auto& [model, s] : by_model) {
      s.label = model;
      s.color = colours[i++ % colours.size()];
      s.marker = viz::Marker::circle;
      c.series.push_back(s);
    }
    panels.push_back(std::move(c));
  }
  return viz::save_chart_grid_png(panels, static_cast<int>(panels.size()), path, "Render study matrix");
}

/// The single study's result of a case, without images: what its chart needs.
study::StudyResult chart_input(const study::MatrixCaseResult& r) {
  study::StudyResult s;
  s.reference_mean = r.reference_mean;
  for (const auto& c : r.candidates) s.candidates.push_back(c.study);
  return s;
}

}  // namespace

const CLI::Validator cloth_tilt(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0') return {};  // not a number: CLI11's conversion says so
      return render::is_cloth_tilt(v) ? std::string()
                                      : fmt::format("must be degrees in {}, got {}", render::cloth_tilt_range(), text);
    },
    render::cloth_tilt_range(), "cloth_tilt");

void add_matrix_options(CLI::App& sub, MatrixCliOptions& o) {
  sub.add_option("--study-cloths", o.cloths,
                 "--study matrix (no scene, no --lighting/--tilt): cloth patterns of weft gen, comma-separated "
                 "(default plain,twill22,stockinette)")
      ->delimiter(',');
  sub.add_option("--study-lightings", o.lightings,
                 "--study matrix: light set-ups, comma-separated (default back,front,grazing)")
      ->delimiter(',');
  sub.add_option("--study-tilts", o.tilts,
                 "--study matrix: views, degrees off the cloth's normal, comma-separated (default 45,8)")
      ->delimiter(',')
      ->check(cloth_tilt);
  sub.add_option("--study-film", o.film, "--study matrix: film WIDTH,HEIGHT (default 96,72; 32,24 with --quick)")
      ->delimiter(',')
      ->check(CLI::Range(study::kMinMatrixFilm, study::kMaxMatrixFilm));
  sub.add_option("--study-yarns", o.yarns,
                 "--study matrix: yarns per side of each cloth (default 4 at 10 um; --quick: 2 at 20 um)")
      ->check(CLI::Range(1, study::kMaxMatrixYarns));
  sub.add_flag("--resume", o.resume,
               "--study matrix: keep the cases a previous run of the same options finished (<out>/matrix.units) "
               "and render only the others; other options are refused");
}

void run_render_matrix_command(const study::StudySpec& study, const MatrixCliOptions& o,
                               const MatrixStudyChoices& given, const Context& ctx, WrittenFiles& files) {
  if (given.study_time) usage_fail("--study-time: the study matrix renders at a fixed --study-spp");
  if (given.output_file) usage_fail("-o: the study matrix writes a folder: give --out DIR");
  // The library's defaults (docs/render.md §6e), then what the command line gave.
  study::MatrixSpec m = study::default_matrix_spec(given.quick);
  if (given.factors) {
    m.study.factors = study.factors;
    m.study.factors_given = true;
  }
  if (given.memory) m.study.memory_rules = study.memory_rules;
  m.study.scale = study.scale;
  m.study.components = study.components;
  if (given.spp > 0) m.study.spp = given.spp;
  if (given.reference_spp > 0) m.study.reference_spp = given.reference_spp;
  m.study.seed = given.seed.value_or(1);
  if (!o.cloths.empty()) m.cloths = o.cloths;
  if (!o.lightings.empty()) {
    m.lightings.clear();
    for (const auto& name : o.lightings) m.lightings.push_back(as_usage([&] { return render::cloth_lighting(name); }));
  }
  if (!o.tilts.empty()) m.tilts = o.tilts;
  if (!o.film.empty()) {
    if (o.film.size() != 2) usage_fail("--study-film: give WIDTH,HEIGHT");
    m.width = o.film[0];
    m.height = o.film[1];
  }
  if (o.yarns > 0) m.yarns = o.yarns;
  const fs::path out = given.out_dir.empty() ? fs::path("render_study") : fs::path(given.out_dir);
  m.study.work_dir = out;
  as_usage([&] { study::check_matrix_spec(m); });
  // `out` is created by study::run_matrix, which removes it again when the run is refused.
  run_render_matrix(m, out, o.resume, ctx, files);
}

void run_render_matrix(study::MatrixSpec spec, const fs::path& out, bool resume, const Context& ctx,
                       WrittenFiles& files) {
  spec.study.work_dir = out;
  study::check_matrix_spec(spec);
  const std::vector<study::MatrixCase> cases = study::matrix_cases(spec);
  // Say the cost before spending it.
  const std::size_t candidates = study::candidate_count(spec.study, spec.study.factors.size());
  const std::string images =
      spec.study.spp > 0
          ? fmt::format("{} candidates x 2 images at {} spp ({:.3g} pixel samples in all)", candidates, spec.study.spp,
                        static_cast<double>(spec.width) * spec.height * static_cast<double>(cases.size()) *
                            (2.0 * static_cast<double>(candidates) * spec.study.spp + spec.study.reference_spp))
          : fmt::format("{} candidates x 2 images of {:g} s (about {} of rendering in all)", candidates,
                        spec.study.seconds,
                        duration_text(2.0 * static_cast<double>(candidates * cases.size()) * spec.study.seconds));
  ctx.say(fmt::format(
      "study matrix: {} cloths x {} light set-ups x {} views = {} cases at {}x{} px, each a reference at {} spp and "
      "{}; {} rank(s) x {} thread(s)",
      spec.cloths.size(), spec.lightings.size(), spec.tilts.size(), cases.size(), spec.width, spec.height,
      spec.study.reference_spp, images, ctx.ranks(), ctx.threads()));
  dist::UnitStore store(out / "matrix.units", study::matrix_key(spec), resume);
  const std::vector<study::MatrixCaseResult> results = study::run_matrix(spec, ctx.progress, &store);
  if (!dist::is_root()) return;
  // The aggregate files appear together or the earlier run's stay (docs/robustness.md "Output
  // folders of failed runs"); the stored cases and cloths above stay either way, for --resume.
  FolderRollback written(out);

  const std::vector<study::MatrixHeadline> headlines = study::matrix_headlines(spec, results);
  const auto text = [&](const std::string& name, const std::string& content, const std::string& what) {
    write_text_atomically(out / name, content);
    files.add(out / name, what);
  };
  text("matrix.csv", study::matrix_csv(results), "per case and candidate: cloth bias, RMSE, noise, memory");
  text("matrix.cost.csv", study::matrix_cost_csv(results), "per case and candidate: time, cost per sample, speed-up");
  text("matrix.json", study::matrix_json(spec, results, headlines), "every case and the headline per cloth");
  text("matrix.md", study::matrix_markdown(headlines, results), "the headline table and the goals");
  const viz::RenderOutcome chart = write_matrix_chart(headlines, out / "matrix.png");
  if (chart.written)
    files.add(out / "matrix.png", "worst cloth bias vs coarsening per cloth");
  else
    ctx.say(fmt::format("no chart {}: {}", (out / "matrix.png").string(), chart.reason));
  for (const auto& r : results) {
    const fs::path p = study::matrix_case_dir(spec, r.c) / "reference.study.png";
    if (write_study_chart(chart_input(r), p, r.c.name).written) files.add(p, "the case's study chart");
  }
  if (store.found() > 0)
    ctx.say(fmt::format("{} of {} cases resumed from {}", store.found(), cases.size(), store.folder().string()));
  // A case's warnings (a clamped window) are said once per cloth: its cases share the grid.
  std::vector<std::string> warnings;
  for (const auto& r : results)
    for (const auto& n : r.notes)
      if (const std::string w = fmt::format("warning: {}: {}", r.c.pattern, n);
          std::find(warnings.begin(), warnings.end(), w) == warnings.end())
        warnings.push_back(w);
  for (const auto& w : warnings) ctx.say(w);
  for (const auto& h : headlines) ctx.say("headline: " + h.text);
  written.keep();
}

}  // namespace weft::app
