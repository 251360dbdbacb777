// `weft fit`: concentration statistics of a grid → gamma laws per axis and isotropic; optional
// least-squares fits to curves from `weft measure`; optional local statistic fields (.vdb).
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "grid_input.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/parse_number.h"
#include "weft/fit/gamma_moments.h"
#include "weft/fit/least_squares.h"
#include "weft/fit/local_fields.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/fit/window_stats.h"
#include "weft/render/cloth_scene.h"
#include "weft/volume/grid.h"
#include "written_files.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct FitOptions {
  GridInputOptions input;
  std::string axes = "x,y,z";
  std::string window = "yarn";
  int block = 0;
  std::string fields = "render";
  std::string beams;
  std::string out = "weft-out";
};

json number_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json fit_json(const fit::GammaFit& g) {
  return {{"mean_concentration", g.mean_concentration}, {"var_concentration", g.var_concentration},
          {"alpha", number_or_null(g.alpha)},           {"beta", number_or_null(g.beta)},
          {"mean_extinction", g.mean_extinction()},     {"exponential_limit", g.exponential()}};
}

/// The axis beams of a beams.csv written by `weft measure`, keyed by label ("+x"), and the labels
/// of its oblique beams (window statistics run along an axis, so those cannot be compared).
struct MeasuredBeams {
  std::map<std::string, volume::TransmittanceCurve> axis;
  std::set<std::string> oblique;
};

MeasuredBeams read_beams(const fs::path& path, const BeamsRecord& now) {
  std::ifstream in(path);
  if (!in) fail("{}: cannot open", path.string());
  std::string line;
  if (!std::getline(in, line)) fail("{}: empty, not a beams.csv from weft measure", path.string());
  check_beams_record(parse_beams_record(line, path.string()), now, path.string());
  if (!std::getline(in, line) || line.rfind("beam,dx,dy,dz,t,T,stderr,logT", 0) != 0) {
    fail("{}: not a beams.csv from weft measure (header 'beam,dx,dy,dz,t,T,stderr,logT')", path.string());
  }
  MeasuredBeams out;
  std::size_t row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    std::vector<double> f;
    std::istringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) {
      // parse_number: a deep beam's T may be subnormal (measure writes 1e-310), which std::stod refused.
      const std::optional<double> x = parse_number(cell);
      if (!x) fail("{}:{}: '{}' is not a number", path.string(), row, cell);
      f.push_back(*x);
    }
    if (f.size() != 8) fail("{}:{}: expected 8 fields, got {}", path.string(), row, f.size());
    const std::array<double, 3> d{f[1], f[2], f[3]};
    if (volume::beam_axis(d) < 0) {  // only axis beams meet window statistics
      out.oblique.insert(volume::direction_label(d));
      continue;
    }
    auto& c = out.axis[volume::direction_label(d)];
    c.direction = d;
    c.depth.push_back(f[4]);
    c.log_t.push_back(f[7]);
    c.rel_stderr.push_back(f[5] > 0.0 ? f[6] / f[5] : 0.0);
  }
  return out;
}

const Registrar kFit{Command{
    "fit", "Gamma-concentration fits (Eq. 19-20) from a grid's concentration statistics", 30,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<FitOptions>();
      add_grid_input(sub, o->input, true);
      sub.add_option("--axes", o->axes, "Axes, comma separated: x, y, z")->capture_default_str();
      sub.add_option("--window", o->window,
                     "Window of the statistics (as weft validate): yarn (the yarn diameter from the grid's "
                     "provenance, else measured), yarn-measured, corr, extent, or a length")
          ->capture_default_str();
      sub.add_option(
             "--block", o->block,
             "Also write local fields per block of B^3 voxels to local_fields.vdb (0 = off); B must stay below the "
             "active box's largest extent (a warning when above its smallest: docs/validate.md \"Local fields\")")
          ->capture_default_str();
      sub.add_option("--fields", o->fields,
                     "With --block: render (mean and variance per axis, the 4 grids the local-gamma medium reads) "
                     "or all (also alpha and beta per axis: 10 grids, for analysis); the variances are stored as "
                     "16-bit floats when they fit (always for concentrations; docs/render.md 5b \"Storage\")")
          ->check(CLI::IsMember({"render", "all"}))
          ->capture_default_str();
      sub.add_option("--beams", o->beams, "beams.csv from `weft measure`: adds least-squares fits and model errors")
          ->check(file_name);
      sub.add_option("--out", o->out,
                     "Output folder (created if missing): fit.json; with --block local_fields.vdb and, for a grid of "
                     "weft gen (the scene takes sigma from its provenance), local_fields_scene.json")
          ->capture_default_str();
      return [o, &sub](const Context& ctx) -> int {
        check_grid_input(o->input);
        as_usage([&] { fit::check_scale_text(o->window, "--window"); });
        if (o->block < 0 || o->block > fit::kMaxLocalBlock)
          usage_fail("--block must be in 0..{} voxels (0 = off), got {}", fit::kMaxLocalBlock, o->block);
        usage_needs(sub, {"--fields"}, o->block > 0, "--block");
        const auto dirs = as_usage([&] { return fit::parse_axes(o->axes); });
        const LoadedGrid loaded = load_grid_input(o->input);
        const volume::Grid& grid = loaded.grid;
        const double sigma = loaded.sigma.sigma;
        // A block the cloth does not fill, before anything is computed (docs/validate.md "Local fields").
        if (o->block > 0) {
          if (const auto whole = fit::whole_box_block(o->block, grid))
            usage_fail(
                "--block {}: {}: the fields would be one homogeneous block, the cloth's concentration spread "
                "over the vacuum around it; use a block below {}",
                o->block, whole->text, whole->below);
          if (const std::string note = fit::thick_block_note(o->block, grid); !note.empty()) ctx.warn(note);
        }
        MeasuredBeams beams;
        if (!o->beams.empty())
          beams =
              read_beams(o->beams, {sigma, o->input.values, grid.voxel_size(), grid.active_voxel_count(), grid.sum()});
        // Every beam of the file is either fitted or named here: none is dropped in silence.
        std::set<std::string> asked;
        for (const auto& d : dirs) asked.insert(volume::direction_label(d));
        std::vector<std::pair<std::string, std::string>> unused;  // beam, why
        for (const auto& label : beams.oblique)
          unused.emplace_back(label, "is not along an axis; window statistics are per axis, so it is not fitted");
        for (const auto& [label, curve] : beams.axis) {
          if (asked.count(label) == 0) unused.emplace_back(label, fmt::format("is not among --axes {}", o->axes));
        }
        if (!o->beams.empty() && beams.axis.size() + beams.oblique.size() == unused.size())
          usage_fail(
              "--beams {}: none of its beams runs along --axes {} (axis beams are fitted per signed axis: pass "
              "e.g. --axes=-z for a -z beam)",
              o->beams, o->axes);
        json not_fitted = json::array();
        for (const auto& [label, why] : unused) {
          ctx.warn(fmt::format("{}: beam {} {}", o->beams, label, why));
          not_fitted.push_back({{"beam", label}, {"reason", why}});
        }
        const auto& measured = beams.axis;
        const fit::StatisticsScale scale = fit::resolve_scale(o->window, grid, loaded.provenance, ctx.progress);
        const fit::ScaleUse scale_used = fit::scale_use(scale, grid, false);
        for (const auto& note : scale_used.notes) ctx.warn(note);

        std::array<fit::ConcentrationStats, 3> stats;
        for (int a = 0; a < 3; ++a)
          stats[static_cast<std::size_t>(a)] =
              fit::window_stats(grid, a, scale.length[static_cast<std::size_t>(a)], ctx.progress);
        const fit::ConcentrationStats iso = fit::pool({stats[0], stats[1], stats[2]});
        const fit::GammaFit iso_fit = fit::gamma_from_moments(iso.mean, iso.variance, sigma);
        json axes = json::array();
        for (const auto& d : dirs) {
          const int a = volume::beam_axis(d);
          const auto& s = stats[static_cast<std::size_t>(a)];
          const fit::GammaFit g = fit::gamma_from_moments(s.mean, s.variance, sigma);
          const std::string label = volume::direction_label(d);
          json j = {
              {"axis", label},
              {"stats", {{"mean", s.mean}, {"variance", s.variance}, {"samples", s.samples}, {"window", s.window}}},
              {"moment", fit_json(g)}};
          const auto it = measured.find(label);
          if (it != measured.end() && it->second.size() < 3) {
            // As in validate: the least-squares reference needs three depths (two parameters and a residual).
            ctx.warn(fmt::format("{}: beam {} has {} depths; the least-squares fit needs 3, so it is not fitted",
                                 o->beams, label, it->second.size()));
          } else if (it != measured.end()) {
            const auto& gt = it->second;
            const auto lsq = fit::fit_gamma_to_curve(gt, sigma, g);
            j["least_squares"] = fit_json(lsq.fit);
            j["least_squares"]["rms_residual_T"] = lsq.rms;
            const auto e_gamma = fit::compare(gt, fit::log_curve(*fit::model_law(g), gt.depth));
            const auto e_exp = fit::compare(gt, fit::log_curve(*fit::exponential_law(g), gt.depth));
            j["rms_abs_T"] = {
                {"gamma", e_gamma.rms_abs_t}, {"least_squares", lsq.rms}, {"exponential", e_exp.rms_abs_t}};
          }
          axes.push_back(j);
          ctx.say(fmt::format("{:<3} window {:.4g}  C = {:.6g}  Var C = {:.6g}  alpha = {:.6g}  beta = {:.6g}", label,
                              s.window, s.mean, s.variance, g.alpha, g.beta));
        }
        ctx.say(fmt::format("iso C = {:.6g}  Var C = {:.6g}  alpha = {:.6g}  beta = {:.6g}", iso.mean, iso.variance,
                            iso_fit.alpha, iso_fit.beta));
        std::optional<fit::LocalFields> fields;
        if (o->block > 0) fields = fit::local_fields(grid, o->block, ctx.progress);
        json report = {{"weft", "fit"},
                       {"grid", fs::absolute(o->input.grid).string()},
                       {"grid_name", grid.name()},
                       {"values", o->input.values},
                       {"sigma", sigma},
                       {"sigma_source", loaded.sigma.source},
                       {"window",
                        {{"rule", scale.rule},
                         {"source", scale.source},
                         {"length", scale.length},
                         {"length_used", scale_used.length}}},
                       {"axes", axes},
                       {"isotropic", {{"mean", iso.mean}, {"variance", iso.variance}, {"fit", fit_json(iso_fit)}}}};
        if (!o->beams.empty()) report["beams_not_fitted"] = not_fitted;
        if (fields)
          report["local_fields"] = {
              {"file", "local_fields.vdb"}, {"block", o->block}, {"blocks", fields->blocks}, {"fields", o->fields}};
        const fs::path out = o->out;
        // Its files appear together, or the folder stays as it was (docs/robustness.md "Output
        // folders of failed runs").
        FolderRollback written(out);
        WrittenFiles files;
        if (fields) {
          const fit::FieldChannels channels = *fit::parse_field_channels(o->fields);  // checked by CLI::IsMember
          fit::save_local_fields(*fields, out / "local_fields.vdb", channels);
          files.add(out / "local_fields.vdb",
                    fmt::format("mean, variance{} per {}^3 block",
                                channels == fit::FieldChannels::all ? ", alpha, beta" : "", o->block));
          // Cloth scenes take σ from the grid's provenance (render::cloth_look): grids of weft gen.
          if (!o->input.extinction() && loaded.provenance.sigma) {
            // A scene that renders the fields as is (`weft render OUT/local_fields_scene.json`),
            // framed and lit like `weft gen`'s scene.json of the fine grid it came from.
            render::ClothSceneMedium medium;
            medium.kind = render::ClothSceneMedium::Kind::local_fields;
            medium.fields = out / "local_fields.vdb";
            write_text_atomically(out / "local_fields_scene.json",
                                  render::cloth_scene_json(o->input.grid, "local_fields.vdb", medium));
            files.add(out / "local_fields_scene.json", "scene: the local-gamma fields for weft render");
          }
        }
        report["outputs"] = files.to_json(out);
        write_text_atomically(out / "fit.json", report.dump(2) + "\n");
        files.add(out / "fit.json", "report");
        written.keep();
        files.say(ctx);
        return 0;
      };
    }}};

}  // namespace
}  // namespace weft::app
