// `weft sim2d`: explicit 2D correlated media and their Monte Carlo transmittance (supplement S.11,
// Figs S.9–S.12). Parses options, runs data_gen/media2d, writes curves.csv, report.json, charts
// and one realization's particles as .vtp.
#include <array>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <tbb/task_group.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "data_gen/media2d/law_fit.h"
#include "data_gen/media2d/simulation.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/number_name.h"
#include "weft/dist/distributed.h"
#include "weft/viz/chart.h"
#include "weft/viz/vtk_files.h"
#include "written_files.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;

using media2d::Curve;
using media2d::EtaResult;
using media2d::SimulationResult;
using media2d::SimulationSpec;

/// Realization 0 of the first eta as points for ParaView, with each particle's radius and cluster.
viz::PointSet particle_points(const SimulationSpec& spec) {
  const media2d::Medium m = media2d::realization(spec, 0, 0);
  viz::PointSet points;
  points.points.reserve(m.centers.size());
  std::vector<double> cluster;
  cluster.reserve(m.centers.size());
  for (std::size_t i = 0; i < m.centers.size(); ++i) {
    points.points.push_back({m.centers[i].x, m.centers[i].y, 0.0});
    const std::size_t index = m.cluster_size > 0 ? i / m.cluster_size : 0;  // the cluster a centre belongs to
    cluster.push_back(static_cast<double>(index));
  }
  points.point_scalars["radius"] = std::vector<double>(m.centers.size(), m.radius);
  points.point_scalars["cluster"] = std::move(cluster);
  return points;
}

struct Sim2dOptions {
  std::vector<double> etas{-0.5, 0.0, 0.5};
  std::string out = "sim2d-out";
  bool quick = false;
  bool paper = false;
  bool no_plot = false;
  bool no_boundary = false;
  std::uint64_t seed = 1;
  double radius = 1e-5;
  double mfp = 0.025;
  std::size_t realizations = 16;
  std::size_t samples = 1000;
  double t_max = 40.0;
  std::size_t bins = 200;
  std::vector<double> thetas{0.0, 30.0, 60.0};
  std::vector<double> eta12{0.0, 0.9};
  double boundary_t = 20.0;
  std::size_t cluster_size = 1000;
  double step_unit = 0.0;
  std::size_t structure_realizations = 1;
  std::size_t structure_max_points = 30000;
};

/// The η part of a file name, "eta+0.5", "eta-0.5", "eta+0.996": the sign always written, the
/// number in the fewest digits that read back as η (weft::signed_number_name), so distinct η
/// never share a file (two digits gave 0.996 and 0.999 one chart, the second over the first).
std::string eta_tag(double eta) { return "eta" + signed_number_name(eta); }

nlohmann::json curve_json(const Curve& c) { return {{"value", c.value}, {"stderr", c.stderr_}}; }

// Long format: one row per (η, quantity, parameter, t).
std::string curves_csv(const SimulationResult& r) {
  std::ostringstream out;
  out << "eta,quantity,param,t,value,stderr\n";
  out.precision(10);
  auto rows = [&](double eta, const char* quantity, const std::string& param, const std::vector<double>& t,
                  const Curve& c) {
    // η is the rows' key: written exactly (number_name), not to the 10 digits of the values.
    const std::string eta_key = number_name(eta);
    for (std::size_t k = 0; k < t.size(); ++k) {
      out << eta_key << ',' << quantity << ',' << param << ',' << t[k] << ',' << c.value[k] << ',' << c.stderr_[k]
          << '\n';
    }
  };
  for (const EtaResult& e : r.etas) {
    for (std::size_t a = 0; a < r.spec.thetas_deg.size(); ++a) {
      const std::string theta = fmt::format("theta={}", r.spec.thetas_deg[a]);
      rows(e.eta, "T_Q", theta, r.edges, e.t_q[a]);
      rows(e.eta, "p_Q", theta, r.centres, e.p_q[a]);
    }
    rows(e.eta, "T_Q", "iso", r.edges, e.t_q_iso);
    rows(e.eta, "p_Q", "iso", r.centres, e.p_q_iso);
    rows(e.eta, "T_S", "iso", r.edges, e.t_s);
    rows(e.eta, "p_S", "iso", r.centres, e.p_s);
    for (const auto& b : e.boundary) {
      const std::string param = fmt::format("eta12={}", b.eta12);
      rows(e.eta, "T_boundary", param, r.edges, b.transmittance);
      rows(e.eta, "p_boundary", param, r.centres, b.pdf);
    }
  }
  return out.str();
}

nlohmann::json report_json(const SimulationResult& r, const nlohmann::json& outputs, const Context& ctx) {
  const SimulationSpec& s = r.spec;
  nlohmann::json j;
  j["tool"] = "weft sim2d";
  j["ranks"] = ctx.ranks();
  j["threads"] = ctx.threads();
  j["units"] = "t in units of the target mean free path lambda; lengths of the medium in unit-square units";
  j["spec"] = {
      {"etas", s.etas},
      {"radius", s.radius},
      {"mean_free_path", s.mean_free_path},
      {"cluster_size", s.cluster_size},
      {"step_unit", s.step_unit == 0.0 ? nlohmann::json("mean spacing 1/sqrt(n)") : nlohmann::json(s.step_unit)},
      {"thetas_deg", s.thetas_deg},
      {"realizations", s.realizations},
      {"samples", s.samples},
      {"t_max", s.t_max},
      {"bins", s.bins},
      {"boundary", s.boundary},
      {"boundary_t", s.boundary_t},
      {"eta12", s.eta12},
      {"structure_realizations", s.structure_realizations},
      {"structure_max_points", s.structure_max_points},
      {"seed", s.seed}};
  j["definitions"] = {
      {"particle_count", "n = 1/(2 r lambda + pi r^2), the solution of Santalo's lambda = (1 - n pi r^2)/(2 n r)"},
      {"T_Q", "sources on the line x = 0 (uniform y, outside disks), direction theta from +x"},
      {"T_Q_iso", "sources uniform in the void, uniform directions (partner of T_S in reciprocity)"},
      {"T_S", "rays leaving the exposed boundary of the disks, exit points uniform, directions cosine-weighted"},
      {"boundary",
       "sources at x = 0 along +x; medium 1 until t_b, then medium 1 translated by omega*s, "
       "s = -log(xi)(1 - eta12)^2 unit-square lengths, one translation per realization"},
      {"stderr", "standard error over realizations"}};
  j["warnings"] = r.warnings;
  j["edges"] = r.edges;
  j["centres"] = r.centres;
  for (const EtaResult& e : r.etas) {
    nlohmann::json je;
    je["eta"] = e.eta;
    je["generator"] = e.generator;
    je["particles"] = e.particles;
    je["santalo_mean_free_path"] = e.santalo_mfp;
    je["poisson_exact_mean_free_path"] = e.exact_poisson_mfp;
    je["step_unit"] = e.step_unit;
    if (e.eta < 0.0) {
      je["lattice"] = {{"nx", e.lattice.nx},
                       {"ny", e.lattice.ny},
                       {"rise_steps", e.lattice.rise_steps},
                       {"rise", e.lattice.rise},
                       {"perturbed_fraction", e.perturbed_fraction}};
    }
    je["ell_q_iso"] = {{"value", e.ell_q_iso}, {"stderr", e.ell_q_iso_stderr}};
    const auto& rec = e.reciprocity;
    je["reciprocity"] = {{"relation", "p_Q(t) = T_S(t)/ell_S"},
                         {"ell_s_measured", rec.ell_s},
                         {"ell_s_measured_stderr", rec.ell_s_stderr},
                         {"t_s_at_t_max", rec.tail_t_s},
                         {"ell_s_fit", rec.ell_s_fit},
                         {"ell_s_fit_stderr", rec.ell_s_fit_stderr},
                         {"chi2", rec.chi2},
                         {"dof", rec.dof},
                         {"max_abs_z", rec.max_abs_z},
                         {"max_abs_z_t", rec.max_abs_z_t},
                         {"residual", rec.residual},
                         {"residual_stderr", rec.residual_stderr}};
    nlohmann::json fits = nlohmann::json::array();
    for (const auto& f : e.fits) {
      nlohmann::json params;
      for (std::size_t i = 0; i < f.names.size(); ++i) {
        params[f.names[i]] = {{"value", f.params[i]}, {"error", f.errors[i]}};
      }
      fits.push_back({{"curve", f.curve},
                      {"law", f.law},
                      {"params", params},
                      {"chi2", f.chi2},
                      {"dof", f.dof},
                      {"bic", media2d::bic(f)},
                      {"converged", f.converged},
                      {"note", f.note}});
    }
    je["fits"] = fits;
    nlohmann::json selection;
    // Selected on the free-path histograms p_Q, p_S (independent bins), reported for T_Q, T_S.
    for (const auto& [label, curve] : {std::pair<const char*, const char*>{"T_Q_iso", "p_Q_iso"}, {"T_S", "p_S"}}) {
      const media2d::LawSelection s = media2d::select_law(e.fits, curve);
      selection[label] = {{"selected", s.selected},
                          {"fitted_to", curve},
                          {"criterion", media2d::LawSelection::kCriterion},
                          {"lowest_chi2", s.lowest_chi2},
                          {"delta_chi2_selected_minus_lowest", s.delta_chi2},
                          {"delta_bic_lowest_chi2_minus_selected", s.delta_bic},
                          {"runner_up", s.runner_up},
                          {"delta_bic_runner_up", s.runner_up_delta_bic}};
    }
    je["law_selection"] = selection;
    nlohmann::json structure = nlohmann::json::array();
    for (const auto& st : e.structure) {
      structure.push_back({{"realization", st.realization},
                           {"points", st.points},
                           {"delaunay_ok", st.delaunay_ok},
                           {"note", st.note},
                           {"distance_unit", "mean spacing d = 1/sqrt(n)"},
                           {"mean_nearest_neighbour", st.mean_nn},
                           {"sd_nearest_neighbour", st.sd_nn},
                           {"poisson_mean_nearest_neighbour", 0.5},
                           {"mean_delaunay_degree", st.mean_delaunay_degree},
                           {"overlapping_fraction", st.max_overlap_fraction},
                           {"nn_edges", st.nn_edges},
                           {"nn_density", st.nn_density},
                           {"g_r", st.g_centres},
                           {"g", st.g}});
    }
    je["structure"] = structure;
    je["curves"] = {{"T_Q_iso", curve_json(e.t_q_iso)}, {"T_S", curve_json(e.t_s)}};
    j["media"].push_back(je);
  }
  j["outputs"] = outputs;
  return j;
}

viz::Series series(std::string label, const std::vector<double>& x, const Curve& c, std::array<unsigned char, 3> color,
                   viz::LineStyle style = viz::LineStyle::solid) {
  viz::Series s;
  s.label = std::move(label);
  s.x = x;
  s.y = c.value;
  s.color = color;
  s.style = style;
  return s;
}

const std::array<std::array<unsigned char, 3>, 6> kPalette{
    {{31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40}, {148, 103, 189}, {140, 86, 75}}};

viz::Series exponential_reference(const SimulationResult& r, double lambda) {
  viz::Series s;
  s.label = "exp(-t/lambda_Santalo)";
  s.x = r.edges;
  for (const double t : r.edges) s.y.push_back(std::exp(-t / lambda));
  s.color = {120, 120, 120};
  s.style = viz::LineStyle::dashed;
  s.width = 1.5f;
  return s;
}

/// One picture: a file name and its panels (side by side).
struct Figure {
  std::string file;
  std::vector<viz::Chart> panels;
};

viz::Chart log_panel(std::string title, std::string y_label) {
  viz::Chart c;
  c.title = std::move(title);
  c.x_label = "t [mean free paths]";
  c.y_label = std::move(y_label);
  c.log_y = true;
  return c;
}

// Transmittances are at most 1: a fixed range down to the sampling floor (half of one count in
// all rays) keeps panels comparable. Densities are per mean free path and may exceed 1, so their
// range is the data's. Empty bins (0 on a log axis) break the lines there.
std::vector<Figure> charts_for(const SimulationResult& r) {
  std::vector<Figure> figures;
  for (const EtaResult& e : r.etas) {
    const std::string tag = eta_tag(e.eta);
    const double floor = 0.5 / static_cast<double>(r.spec.samples * r.spec.realizations);
    const std::pair<double, double> t_range{floor, 1.2};
    // Fig. S.9: T_Q per source angle.
    viz::Chart tq = log_panel(fmt::format("T_Q(t) from sources, eta = {} ({})", e.eta, e.generator), "T_Q");
    tq.y_range = t_range;
    for (std::size_t a = 0; a < e.t_q.size(); ++a) {
      tq.series.push_back(series(fmt::format("theta = {} deg", r.spec.thetas_deg[a]), r.edges, e.t_q[a],
                                 kPalette[a % kPalette.size()]));
    }
    tq.series.push_back(series("isotropic", r.edges, e.t_q_iso, kPalette[5]));
    tq.series.push_back(exponential_reference(r, e.santalo_mfp));
    figures.push_back({fmt::format("tq_{}.png", tag), {std::move(tq)}});
    // Fig. S.10: p_S and T_S from scatterers, each on its own axis (different units).
    viz::Chart ps = log_panel(fmt::format("p_S(t) from scatterers, eta = {}", e.eta), "p_S [1/mean free path]");
    ps.series.push_back(series("p_S", r.centres, e.p_s, kPalette[0]));
    viz::Chart ts = log_panel(fmt::format("T_S(t) from scatterers, eta = {}", e.eta), "T_S");
    ts.y_range = t_range;
    ts.series.push_back(series("T_S", r.edges, e.t_s, kPalette[1]));
    ts.series.push_back(exponential_reference(r, e.santalo_mfp));
    figures.push_back({fmt::format("ts_{}.png", tag), {std::move(ps), std::move(ts)}});
    // Figs. S.11–S.12: medium-to-medium boundary; T and p each on its own axis.
    if (!e.boundary.empty()) {
      viz::Chart bt = log_panel(fmt::format("T across a boundary at t = {}, eta1 = {}", r.spec.boundary_t, e.eta), "T");
      viz::Chart bp =
          log_panel(fmt::format("p across a boundary at t = {}, eta1 = {}", r.spec.boundary_t, e.eta), "p [1/mfp]");
      bt.y_range = t_range;
      bt.vertical_lines = {r.spec.boundary_t};
      bp.vertical_lines = {r.spec.boundary_t};
      for (std::size_t b = 0; b < e.boundary.size(); ++b) {
        const auto color = kPalette[b % kPalette.size()];
        bt.series.push_back(
            series(fmt::format("eta12 = {}", e.boundary[b].eta12), r.edges, e.boundary[b].transmittance, color));
        bp.series.push_back(series(fmt::format("eta12 = {}", e.boundary[b].eta12), r.centres, e.boundary[b].pdf, color,
                                   viz::LineStyle::dotted));
      }
      figures.push_back({fmt::format("boundary_{}.png", tag), {std::move(bt), std::move(bp)}});
    }
  }
  for (Figure& f : figures) {
    for (viz::Chart& c : f.panels) {
      // Two panels side by side at the size one chart had.
      c.width = f.panels.size() > 1 ? 800 : 1000;
      c.height = f.panels.size() > 1 ? 620 : 700;
    }
  }
  return figures;
}

const Registrar kSim2d{Command{
    "sim2d", "Simulate explicit 2D correlated media: T_Q, p_S/T_S, boundaries, reciprocity (S.11)", 60,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<Sim2dOptions>();
      // Each value checked here, so the error names --eta (media2d::validate's own check of the
      // spec, "medium: eta must be in [-1, 1)", names no option).
      sub.add_option("--eta", o->etas, "Degrees of correlation, comma-separated, each in [-1, 1)")
          ->delimiter(',')
          ->check(in_range(-1.0, 1.0, false))
          ->capture_default_str();
      sub.add_option("--out", o->out,
                     "Output folder (created if missing): curves.csv, report.json, particles_eta*.vtp, charts *.png")
          ->capture_default_str();
      sub.add_flag("--quick", o->quick,
                   "Small fast run for tests: r = 1e-4, 8 realizations x 400 samples, t-max 20, boundary at 4 (where "
                   "enough of the few rays still fly for the boundary to show)");
      sub.add_flag("--paper", o->paper, "The paper's setting: 2000 realizations x 1000 samples (slow)");
      sub.add_option("--seed", o->seed, "Run seed; results do not depend on --threads")->capture_default_str();
      sub.add_option("--radius", o->radius, "Disk radius r, unit-square units, > 0")->capture_default_str();
      sub.add_option(
             "--mfp", o->mfp,
             "Target mean free path lambda, unit-square units; sets n = 1/(2 r lambda + pi r^2) and the unit of t")
          ->capture_default_str();
      sub.add_option("--realizations", o->realizations, "Media generated per eta, >= 1")->capture_default_str();
      sub.add_option("--samples", o->samples, "Rays per quantity per realization")->capture_default_str();
      sub.add_option("--t-max", o->t_max,
                     "Longest free path measured, in mean free paths (refused past 100 domain lengths, 4000 at the "
                     "defaults: docs/sim2d.md \"Rays\")")
          ->capture_default_str();
      sub.add_option("--bins", o->bins, "Bins over [0, t-max]")->capture_default_str();
      sub.add_option("--theta", o->thetas, "Source angles from +x in degrees, comma-separated")
          ->delimiter(',')
          ->capture_default_str();
      sub.add_option("--eta12", o->eta12,
                     "Correlation of the second medium with the first, each in [0, 1] (1 = same medium)")
          ->delimiter(',')
          ->capture_default_str();
      sub.add_option("--boundary-t", o->boundary_t, "Distance of the medium-to-medium boundary, mean free paths")
          ->capture_default_str();
      sub.add_flag("--no-boundary", o->no_boundary, "Skip the medium-to-medium boundary experiment");
      sub.add_option("--cluster-size", o->cluster_size, "Particles per random-walk cluster (eta > 0)")
          ->capture_default_str();
      sub.add_option("--step-unit", o->step_unit,
                     "Length unit of perturbation / walk steps, unit-square units (0 = mean spacing 1/sqrt(n))")
          ->capture_default_str();
      sub.add_option("--structure-realizations", o->structure_realizations,
                     "Realizations per eta whose structure (CGAL nearest neighbours, g(r)) is analysed")
          ->capture_default_str();
      sub.add_option("--structure-max-points", o->structure_max_points,
                     "Above this many particles, structure is measured on a stand-in realization of this size")
          ->capture_default_str();
      sub.add_flag("--no-plot", o->no_plot, "Write no PNG charts");
      return [o, &sub](const Context& ctx) -> int {
        SimulationSpec spec;
        spec.etas = o->etas;
        spec.radius = o->radius;
        spec.mean_free_path = o->mfp;
        spec.realizations = o->realizations;
        spec.samples = o->samples;
        spec.t_max = o->t_max;
        spec.bins = o->bins;
        spec.thetas_deg = o->thetas;
        spec.eta12 = o->eta12;
        spec.boundary_t = o->boundary_t;
        spec.boundary = !o->no_boundary;
        spec.cluster_size = o->cluster_size;
        spec.step_unit = o->step_unit;
        spec.structure_realizations = o->structure_realizations;
        spec.structure_max_points = o->structure_max_points;
        spec.seed = o->seed;
        if (o->quick && o->paper) usage_fail("sim2d: --quick and --paper exclude each other");
        usage_needs(sub, {"--boundary-t", "--eta12"}, !o->no_boundary, "the boundary experiment (no --no-boundary)");
        // Presets fill only what the user did not set explicitly.
        auto unset = [&sub](const char* name) { return sub.count(name) == 0; };
        if (o->quick) {
          if (unset("--radius")) spec.radius = 1e-4;
          if (unset("--realizations")) spec.realizations = 8;
          if (unset("--samples")) spec.samples = 400;
          if (unset("--t-max")) spec.t_max = 20.0;
          if (unset("--bins")) spec.bins = 80;
          if (unset("--boundary-t")) spec.boundary_t = 4.0;
        }
        if (o->paper) {
          if (unset("--realizations")) spec.realizations = 2000;
          if (unset("--samples")) spec.samples = 1000;
        }
        // Options of generators or passes this run does not have would do nothing (docs/sim2d.md).
        const auto any_eta = [&](auto&& pred) { return std::any_of(spec.etas.begin(), spec.etas.end(), pred); };
        usage_needs(sub, {"--cluster-size"}, any_eta([](double e) { return e > 0.0; }),
                    "a positively correlated medium (an --eta above 0: random-walk clusters)");
        usage_needs(sub, {"--step-unit"}, any_eta([](double e) { return e != 0.0 && e != -1.0; }),
                    "a correlated medium with steps (an --eta other than 0 and -1)");
        usage_needs(sub, {"--structure-max-points"}, std::min(spec.structure_realizations, spec.realizations) > 0,
                    "a structure pass (--structure-realizations above 0)");
        // The spec holds option values only: what it refuses is a usage error (exit 2).
        as_usage([&] { media2d::validate(spec); });
        const fs::path out(o->out);
        // Made now, so a bad --out fails before the run; removed again if the run fails.
        std::optional<FolderRollback> folder;
        if (dist::is_root()) folder.emplace(out);

        // One realization's particles (realization 0 of the first eta) for ParaView, made and
        // compressed in memory beside the realizations' units on rank 0, by a thread they leave
        // free: done after them, it was the longest serial step of a run (docs/benchmarks.md
        // "Every core busy: the sweep's serial pieces"). Written with the other files once every
        // unit succeeded; an exception in the units cancels and waits for it.
        const std::string particles_name = fmt::format("particles_{}.vtp", eta_tag(spec.etas.front()));
        std::optional<std::string> particles;
        std::exception_ptr particles_failure;
        tbb::task_group beside;
        if (dist::is_root()) {
          beside.run([&] {
            try {
              particles = viz::vtp_bytes(particle_points(spec), out / particles_name);
            } catch (...) {
              particles_failure = std::current_exception();
            }
          });
        }
        const SimulationResult result = media2d::simulate(spec, ctx.progress);
        beside.wait();
        if (!dist::is_root()) return 0;  // rank 0 reduced the realizations and writes everything
        if (particles_failure) std::rethrow_exception(particles_failure);

        nlohmann::json outputs;
        WrittenFiles files;
        write_text_atomically(out / "curves.csv", curves_csv(result));
        files.add(out / "curves.csv", "curves per eta");
        outputs["curves"] = "curves.csv";

        write_text_atomically(out / particles_name, *particles);
        files.add(out / particles_name, "one realization's particles");
        outputs["particles"] = particles_name;

        // The data files are complete before any picture is attempted.
        outputs["charts"] = nlohmann::json::array();
        write_text_atomically(out / "report.json", report_json(result, outputs, ctx).dump(2) + "\n");
        nlohmann::json charts = nlohmann::json::array();
        if (!o->no_plot) {
          for (const auto& [name, panels] : charts_for(result)) {
            const viz::RenderOutcome outcome =
                viz::save_chart_grid_png(panels, static_cast<int>(panels.size()), out / name);
            charts.push_back({{"file", name}, {"written", outcome.written}, {"reason", outcome.reason}});
            if (outcome.written) files.add(out / name, "chart");
            if (!outcome.written) ctx.say(fmt::format("chart {} not written: {}", name, outcome.reason));
          }
        }
        outputs["charts"] = charts;
        outputs["files"] = files.to_json(out);
        write_text_atomically(out / "report.json", report_json(result, outputs, ctx).dump(2) + "\n");
        files.add(out / "report.json", "report");

        for (const auto& w : result.warnings) ctx.say("warning: " + w);
        for (const EtaResult& e : result.etas) {
          const auto& rec = e.reciprocity;
          // Parsimony: the lowest BIC, not the lowest chi2 (law_fit.h); the runner-up is named too.
          const media2d::LawSelection sel = media2d::select_law(e.fits, "p_Q_iso");
          std::string best = sel.selected;
          if (!sel.runner_up.empty())
            best += fmt::format(" (BIC; next {} +{:.1f})", sel.runner_up, sel.runner_up_delta_bic);
          if (sel.lowest_chi2 != sel.selected)
            best += fmt::format(", {} has chi2 lower by {:.2f} with more parameters", sel.lowest_chi2, sel.delta_chi2);
          ctx.say(
              fmt::format("eta {:<6} {:<11} n = {:>8}  ell_Q = {:.3f} +- {:.3f}  ell_S = {:.3f} +- {:.3f}  "
                          "reciprocity chi2/dof = {:.1f}/{}  best law for T_Q: {}",
                          signed_number_name(e.eta), e.generator, e.particles, e.ell_q_iso, e.ell_q_iso_stderr,
                          rec.ell_s_fit, rec.ell_s_fit_stderr, rec.chi2, rec.dof, best));
        }
        ctx.say(fmt::format("{} realization(s) per eta on {} rank(s) x {} thread(s)", spec.realizations, ctx.ranks(),
                            ctx.threads()));
        files.say(ctx);
        folder->keep();
        return 0;
      };
    },
    /*distributed=*/true}};

}  // namespace
}  // namespace weft::app
