// `weft validate`: the main job (supplement Fig. S.13) — beams through a voxelized cloth (or any
// grid), ground truth by DDA, gamma model from concentration statistics, exponential baseline.
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "data_gen/cloth/cloth.h"
#include "validate_common.h"
#include "validate_sweep.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/fit/sweep.h"
#include "weft/fit/validation.h"
#include "weft/viz/chart.h"
#include "weft/viz/display.h"
#include "weft/viz/volume_view.h"
#include "weft/viz/vtk_files.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct ValidateOptions {
  std::string grid;
  std::string grid_name;
  std::string values = "concentration";
  std::string cloth;
  std::string axes = "x,y,z";
  int rays = 1;
  double sigma = 0.0;
  CLI::Option* sigma_option = nullptr;  ///< tells "not given" from an invalid 0
  std::string window = "corr";
  bool no_plot = false;
  std::uint64_t seed = 1;
  std::string method = "auto";
  std::string out = "weft-out";
  bool sweep = false;
  bool quick = false;
};

json fit_json(const fit::GammaFit& g) {
  return {{"mean_concentration", g.mean_concentration}, {"var_concentration", g.var_concentration},
          {"alpha", number_or_null(g.alpha)},           {"beta", number_or_null(g.beta)},
          {"mean_extinction", g.mean_extinction()},     {"exponential_limit", g.exponential()}};
}

json error_json(const fit::CurveError& e) {
  return {{"max_abs_T", e.max_abs_t},          {"rms_abs_T", e.rms_abs_t},
          {"max_abs_logT", e.max_abs_log_t},   {"rms_abs_logT", e.rms_abs_log_t},
          {"mean_logT_bias", e.mean_log_bias}, {"fraction_below_ground_truth", e.below_fraction},
          {"logT_points", e.log_points}};
}

json stats_json(const fit::ConcentrationStats& s) {
  return {{"mean", s.mean},
          {"variance", s.variance},
          {"samples", s.samples},
          {"window", s.window},
          {"window_voxels", s.window_voxels}};
}

/// curves.csv: one row per depth of the longest axis; shorter axes leave blanks.
std::string curves_csv(const fit::Validation& v) {
  std::size_t rows = 0;
  const fit::AxisValidation* longest = nullptr;
  for (const auto& a : v.axes) {
    if (a.ground_truth.size() > rows) {
      rows = a.ground_truth.size();
      longest = &a;
    }
  }
  std::string out = "t";
  for (const auto& a : v.axes) {
    const std::string s = a.label;
    out += fmt::format(",T_gt_{0},stderr_{0},logT_gt_{0},gamma_{0}", s);
    for (const auto& m : a.models) {
      if (m.name == "least-squares") out += fmt::format(",lsq_{}", s);
    }
  }
  if (v.has_isotropic) out += ",isotropic";
  out += ",exponential\n";
  const auto iso = v.has_isotropic ? fit::model_law(v.isotropic_fit) : nullptr;
  const auto expo = fit::exponential_law(v.exponential);
  for (std::size_t k = 0; k < rows; ++k) {
    const double t = longest->ground_truth.depth[k];
    out += fmt_csv(t);
    for (const auto& a : v.axes) {
      const auto& gt = a.ground_truth;
      if (k < gt.size()) {
        out += fmt::format(",{},{},{},{}", fmt_csv(gt.transmittance(k)), fmt_csv(gt.stderr_abs(k)),
                           fmt_csv(gt.log_t[k]), fmt_csv(std::exp(a.model("gamma").log_t[k])));
        for (const auto& m : a.models) {
          if (m.name == "least-squares") out += fmt::format(",{}", fmt_csv(std::exp(m.log_t[k])));
        }
      } else {
        out += ",,,,";
        for (const auto& m : a.models) {
          if (m.name == "least-squares") out += ",";
        }
      }
    }
    if (iso) out += fmt::format(",{}", fmt_csv(iso->transmittance(t)));
    out += fmt::format(",{}\n", fmt_csv(expo->transmittance(t)));
  }
  return out;
}

viz::Chart transmittance_chart(const fit::Validation& v, const std::string& title, const std::string& unit) {
  viz::Chart c;
  c.title = title;
  c.x_label = fmt::format("depth t [{}]", unit);
  c.y_label = "transmittance T(t)";
  c.log_y = true;
  double tmax = 0.0;
  double tmin_plot = 1.0;
  for (const auto& a : v.axes) {
    const auto& gt = a.ground_truth;
    tmax = std::max(tmax, gt.depth.back());
    viz::Series s;
    s.label = fmt::format("ground truth {}", a.label);
    s.x = gt.depth;
    for (std::size_t k = 0; k < gt.size(); ++k) {
      s.y.push_back(gt.transmittance(k));
      if (s.y.back() > 0.0) tmin_plot = std::min(tmin_plot, s.y.back());
    }
    s.color = axis_color(a.direction);
    c.series.push_back(s);
    viz::Series m;
    m.label = fmt::format("gamma model {}", a.label);
    m.x = gt.depth;
    for (double l : a.model("gamma").log_t) m.y.push_back(std::exp(l));
    m.color = s.color;
    m.style = viz::LineStyle::dotted;
    c.series.push_back(m);
  }
  std::vector<double> ts;
  const std::size_t n = 200;
  for (std::size_t k = 0; k <= n; ++k) ts.push_back(tmax * static_cast<double>(k) / static_cast<double>(n));
  if (v.has_isotropic) {
    viz::Series iso;
    iso.label = "isotropic gamma";
    iso.x = ts;
    const auto law = fit::model_law(v.isotropic_fit);
    for (double t : ts) iso.y.push_back(law->transmittance(t));
    iso.color = {0, 0, 0};
    iso.style = viz::LineStyle::dotted;
    c.series.insert(c.series.begin(), iso);  // under the per-axis models
  }
  viz::Series e;
  e.label = "exponential (RTE)";
  e.x = ts;
  const auto law = fit::exponential_law(v.exponential);
  for (double t : ts) e.y.push_back(law->transmittance(t));
  e.color = {140, 40, 180};
  c.series.push_back(e);
  // Down to 1e-3 at least, so the exponential baseline's fall shows (as in Fig. S.13).
  c.y_range = std::make_pair(std::max(1e-12, std::min(1e-3, 0.5 * tmin_plot)), 1.1);
  c.x_range = std::make_pair(0.0, tmax);
  return c;
}

/// accuracy_time.csv: one row per (axis, method, factor, ray fraction).
const Registrar kValidate{Command{
    "validate", "Ground-truth beams vs gamma and exponential models (Fig. S.13), default: built-in cloth", 5,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<ValidateOptions>();
      auto* grid = sub.add_option("--grid", o->grid, "Use this .vdb grid instead of generating a cloth");
      sub.add_option("--grid-name", o->grid_name, "Grid to read from --grid (default: the first float grid)")
          ->needs(grid);
      sub.add_option("--values", o->values,
                     "Meaning of the grid's values: concentration (mu = sigma*C) or extinction (mu)")
          ->check(CLI::IsMember({"concentration", "extinction"}))
          ->capture_default_str();
      sub.add_option("--cloth", o->cloth, "cloth.json to generate (default: the built-in plain weave)")->excludes(grid);
      sub.add_option("--axes", o->axes, "Beam axes, comma separated: x, y, z, optionally signed (-z)")
          ->capture_default_str();
      sub.add_option("--rays", o->rays, "Rays per column (> 1: jittered; axis rays of one column see the same voxels)")
          ->capture_default_str();
      o->sigma_option = sub.add_option(
          "--sigma", o->sigma,
          "Extinction cross-section per unit concentration [1/length]; default for a cloth 2/(pi r_fibre) "
          "(opaque fibres across the beam), 1 for a grid");
      sub.add_option("--window", o->window,
                     "Window of the concentration statistics: corr (each axis's correlation length, measured from "
                     "the grid), extent (the whole depth along each beam), or a length")
          ->capture_default_str();
      sub.add_flag("--no-plot", o->no_plot, "Do not render transmittance.png and cloth.png");
      sub.add_option("--seed", o->seed, "Seed of the cloth generator and jittered rays")->capture_default_str();
      sub.add_option("--method", o->method, "Beam tracing: auto | streaming | per-ray | openvdb")
          ->capture_default_str();
      sub.add_option("--out", o->out, "Output folder")->capture_default_str();
      sub.add_flag("--sweep", o->sweep,
                   "Accuracy vs time instead of the validation: reference beams, 1/4 and 1/16 of the rays, and "
                   "exponential and gamma models on grids downsampled 2, 4, 8, 16 times (accuracy_time.csv/.png)");
      sub.add_flag("--quick", o->quick, "With --sweep: one timing run instead of the median of 3")
          ->needs(sub.get_option("--sweep"));
      return [o](const Context& ctx) -> int {
        const auto t_start = std::chrono::steady_clock::now();
        json timings = json::object();
        // Everything is checked and computed before the output folder is touched.
        if (o->rays < 1) usage_fail("--rays must be >= 1, got {}", o->rays);
        const bool sigma_given = o->sigma_option->count() > 0;
        if (sigma_given) usage_positive("--sigma", o->sigma);
        const bool extinction = o->values == "extinction";
        if (extinction && sigma_given) usage_fail("--sigma applies to concentration values, not --values extinction");
        if (extinction && o->grid.empty())
          usage_fail("--values extinction needs --grid (a cloth grid holds concentrations)");
        fit::ValidationSpec spec;
        spec.directions = as_usage([&] { return fit::parse_axes(o->axes); });
        spec.rays_per_column = o->rays;
        if (o->window == "corr") {
          spec.window = fit::ValidationSpec::kCorrelationWindow;
        } else if (o->window == "extent") {
          spec.window = 0.0;
        } else {
          try {
            std::size_t used = 0;
            spec.window = std::stod(o->window, &used);
            if (used != o->window.size()) throw std::invalid_argument(o->window);
          } catch (const std::exception&) {
            usage_fail("--window: '{}' is not corr, extent or a length", o->window);
          }
          usage_positive("--window", spec.window);
        }
        spec.seed = o->seed;
        spec.method = as_usage([&] { return volume::parse_beam_method(o->method); });

        json input;
        volume::Grid grid;
        std::string title;
        if (!o->grid.empty()) {
          const auto t0 = std::chrono::steady_clock::now();
          grid = volume::Grid::load(o->grid, o->grid_name);
          timings["load_grid"] = seconds_since(t0);
          if (grid.active_voxel_count() == 0) fail("{}: grid '{}' is empty (no active voxels)", o->grid, grid.name());
          input = {{"source", "grid"}, {"file", fs::absolute(o->grid).string()}, {"grid_name", grid.name()}};
          spec.sigma = extinction ? 1.0 : (sigma_given ? o->sigma : 1.0);
          title = fmt::format("{} ({})", fs::path(o->grid).filename().string(), grid.name());
        } else {
          cloth::ClothSpec cs = o->cloth.empty() ? cloth::default_cloth_spec() : cloth::load_cloth_spec(o->cloth);
          if (o->cloth.empty()) cs.seed = o->seed;
          const auto t0 = std::chrono::steady_clock::now();
          cloth::ClothBuild build = cloth::build_cloth(cs, ctx.progress);
          timings["cloth_total"] = seconds_since(t0);
          timings["cloth_generate"] = build.report.generate_seconds;
          timings["cloth_voxelize"] = build.report.voxelize_seconds;
          grid = build.grid;
          if (grid.active_voxel_count() == 0) fail("cloth: the voxelized cloth is empty");
          const double r = build.spec.warp_yarn.fiber_radius;
          spec.sigma = sigma_given ? o->sigma : 2.0 / (std::numbers::pi * r);
          input = {{"source", "cloth"},
                   {"cloth_file", o->cloth.empty() ? json(nullptr) : json(fs::absolute(o->cloth).string())},
                   {"cloth", json::parse(cloth::cloth_spec_json(build.spec))},
                   {"voxelize",
                    {{"fiber_volume", build.report.fiber_volume},
                     {"grid_volume", build.report.grid_volume},
                     {"relative_error", build.report.relative_error},
                     {"overlap_fraction", build.report.overlap_fraction},
                     {"fiber_count", build.report.fiber_count}}}};
          title =
              fmt::format("{} cloth, {}x{} yarns", build.spec.pattern, build.spec.warp_count, build.spec.weft_count);
        }
        if (o->sweep) return run_sweep({o->out, o->no_plot, o->quick}, ctx, grid, spec, title, input, timings, t_start);
        const fit::Validation v = fit::validate(grid, spec, ctx.progress);

        // Texts first (in memory), then files.
        const auto box = grid.active_bbox();
        input["values"] = o->values;
        input["voxel_size"] = grid.voxel_size();
        input["active_voxels"] = grid.active_voxel_count();
        input["bbox_index"] = {{"min", box.min}, {"max", box.max}};
        input["origin"] = grid.origin();
        json report;
        report["weft"] = "validate";
        report["units"] = "lengths in the grid's world units (mm for cloth); sigma in 1/length";
        report["input"] = input;
        report["sigma"] = spec.sigma;
        report["sigma_default"] = !sigma_given && !extinction;
        report["rays_per_column"] = spec.rays_per_column;
        report["seed"] = spec.seed;
        report["window"] = o->window == "corr"     ? json("correlation length along each beam")
                           : o->window == "extent" ? json("extent of the grid along each beam")
                                                   : json(spec.window);
        report["window_meaning"] =
            "per-ray mean concentration over every window of this length along every column (stride one voxel)";
        report["mean_concentration_bbox"] = v.mean_concentration;
        report["exponential"] = fit_json(v.exponential);
        if (v.has_isotropic) {
          report["isotropic"] = {{"stats", stats_json(v.isotropic_stats)}, {"fit", fit_json(v.isotropic_fit)}};
          timings["isotropic_stats"] = v.isotropic_seconds;
        }
        json axes = json::array();
        bool all_pass = true;
        for (const auto& a : v.axes) {
          json j;
          j["axis"] = a.label;
          j["rays"] = a.ground_truth.rays;
          j["method"] = a.ground_truth.method;
          j["depth_max"] = a.ground_truth.depth.back();
          j["stats"] = stats_json(a.stats);
          if (o->window == "corr") j["correlation_length"] = a.correlation_length;
          j["fits"] = {{"moment", fit_json(a.moment_fit)}};
          json errors;
          for (const auto& m : a.models) errors[m.name] = error_json(m.error);
          if (spec.least_squares) {
            j["fits"]["least_squares"] = fit_json(a.lsq_fit.fit);
            j["fits"]["least_squares"]["rms_residual_T"] = a.lsq_fit.rms;
            j["fits"]["least_squares"]["converged"] = a.lsq_fit.converged;
          }
          if (v.has_isotropic) j["fits"]["isotropic"] = fit_json(v.isotropic_fit);
          j["errors"] = errors;
          const double g = a.model("gamma").error.rms_abs_t;
          const double e = a.model("exponential").error.rms_abs_t;
          const bool pass = g <= e / 3.0 && a.model("exponential").error.mean_log_bias < 0.0;
          all_pass = all_pass && pass;
          j["gamma_over_exponential_rms_T"] = e > 0.0 ? json(g / e) : json(nullptr);
          j["exponential_overestimates_extinction"] = a.model("exponential").error.mean_log_bias < 0.0;
          j["acceptance_gamma_rms_at_most_third_of_exponential"] = pass;
          j["timings"] = {{"beam", a.beam_seconds}, {"stats", a.stats_seconds}, {"fits", a.fit_seconds}};
          timings[fmt::format("beam_{}", a.label)] = a.beam_seconds;
          axes.push_back(j);
        }
        report["axes"] = axes;
        report["acceptance_all_axes"] = all_pass;
        const std::string csv = curves_csv(v);

        const fs::path out = o->out;
        ensure_directory(out);
        auto t0 = std::chrono::steady_clock::now();
        write_text_atomically(out / "curves.csv", csv);
        json outputs = {{"curves.csv", "written"}};
        if (o->grid.empty()) {
          // The generated grid, so `weft measure` and `weft fit` can run the stages alone on it.
          grid.save(out / "cloth.vdb");
          outputs["cloth.vdb"] = "written";
        }
        try {
          viz::write_vti(grid, out / "cloth.vti");
          outputs["cloth.vti"] = "written";
        } catch (const Error& e) {
          outputs["cloth.vti"] = fmt::format("skipped: {}", e.what());
        }
        timings["write_data"] = seconds_since(t0);
        // report.json goes out before the plots too: a renderer that dies takes nothing with it.
        report["outputs"] = outputs;
        report["timings_seconds"] = timings;
        write_text_atomically(out / "report.json", report.dump(2) + "\n");
        if (o->no_plot) {
          outputs["transmittance.png"] = "skipped: --no-plot";
          outputs["cloth.png"] = "skipped: --no-plot";
        } else {
          t0 = std::chrono::steady_clock::now();
          std::string why;
          if (!viz::ensure_display(&why)) {
            outputs["transmittance.png"] = fmt::format("not rendered: {}", why);
            outputs["cloth.png"] = fmt::format("not rendered: {}", why);
          } else {
            const auto chart = viz::save_chart_png(
                transmittance_chart(v, title, o->grid.empty() ? "mm" : "length units"), out / "transmittance.png");
            outputs["transmittance.png"] =
                chart.written ? std::string("written") : fmt::format("not rendered: {}", chart.reason);
            viz::VolumeView view;
            view.title = title;
            for (const auto& a : v.axes)
              view.arrows.push_back({a.direction, axis_color(a.direction), fmt::format("beam {}", a.label)});
            const auto pic = viz::save_volume_png(grid, view, out / "cloth.png");
            outputs["cloth.png"] = pic.written ? std::string("written") : fmt::format("not rendered: {}", pic.reason);
          }
          timings["plots"] = seconds_since(t0);
        }
        timings["total"] = seconds_since(t_start);
        report["outputs"] = outputs;
        report["timings_seconds"] = timings;
        write_text_atomically(out / "report.json", report.dump(2) + "\n");

        // Summary table.
        ctx.say(fmt::format("weft validate: {}; sigma = {:.6g}/length, {} active voxels of {:.4g}", title, spec.sigma,
                            grid.active_voxel_count(), grid.voxel_size()));
        ctx.say(fmt::format(
            "active: beams {}, window stats{}, moment gamma fits, least-squares fits, exponential "
            "baseline{}",
            o->axes, v.has_isotropic ? " (all axes, for isotropic)" : "", o->no_plot ? "; plots off" : "; plots"));
        ctx.say(fmt::format("{:<5} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>7}  {}", "axis", "rays", "alpha",
                            "RMS T gam", "RMS T exp", "RMS T lsq", "RMS T iso", "gam/exp", "exp overestimates"));
        for (const auto& a : v.axes) {
          const double g = a.model("gamma").error.rms_abs_t;
          const double e = a.model("exponential").error.rms_abs_t;
          ctx.say(fmt::format("{:<5} {:>9} {:>10.4g} {:>10.3e} {:>10.3e} {:>10.3e} {:>10.3e} {:>7.3f}  {}", a.label,
                              a.ground_truth.rays, a.moment_fit.alpha, g, e, a.model("least-squares").error.rms_abs_t,
                              v.has_isotropic ? a.model("isotropic").error.rms_abs_t : NAN, e > 0 ? g / e : NAN,
                              a.model("exponential").error.mean_log_bias < 0.0 ? "yes" : "no"));
        }
        std::string stages;
        for (auto it = timings.begin(); it != timings.end(); ++it) {
          stages += fmt::format("{}{} {:.2f}s", stages.empty() ? "" : ", ", it.key(), it.value().get<double>());
        }
        ctx.say(fmt::format("timings: {}", stages));
        for (auto it = outputs.begin(); it != outputs.end(); ++it) {
          const std::string status = it.value().get<std::string>();
          if (status != "written" && status.find("--no-plot") == std::string::npos)
            fmt::print(stderr, "weft validate: note: {} {}\n", it.key(), status);
        }
        ctx.say(fmt::format("wrote {}", (out / "report.json").string()));
        return 0;
      };
    }}};

}  // namespace
}  // namespace weft::app
