// `weft validate`: the main job (supplement Fig. S.13) — beams through a voxelized cloth (or any
// grid), ground truth by DDA, the paper's gamma law and the predictive models of fit/models.h
// from the voxels alone at the yarn scale, the exponential baseline; --corpus runs it over every
// pattern × yarn preset × voxel size.
#include <chrono>
#include <cmath>
#include <optional>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/grid_fibres.h"
#include "grid_input.h"
#include "validate_common.h"
#include "validate_corpus.h"
#include "validate_fibres.h"
#include "validate_output.h"
#include "validate_sweep.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/dist/distributed.h"
#include "weft/fit/report.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/study/model_scenes.h"
#include "weft/viz/display.h"
#include "weft/viz/volume_view.h"
#include "weft/viz/vtk_files.h"
#include "weft/volume/beam_checks.h"
#include "written_files.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct ValidateOptions {
  GridInputOptions input;
  std::string cloth;
  std::string axes = "x,y,z";
  int rays = 1;
  std::string window = "yarn";
  bool no_plot = false;
  bool no_vti = false;
  std::uint64_t seed = 1;
  std::string method = "auto";
  std::string out = "weft-out";
  bool sweep = false;
  bool corpus = false;
  bool quick = false;
  bool resume = false;
  std::vector<std::string> cases;
  bool scenes = false;
  bool fibres = false;  // the fibre ground truth beside T_gt (validate_fibres.h)
  std::string models = "all";
};

const Registrar kValidate{Command{
    "validate",
    "Ground-truth beams vs the gamma law, predictive models and the exponential (Fig. S.13), default: built-in "
    "cloth",
    5,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<ValidateOptions>();
      add_grid_input(sub, o->input, false);
      sub.add_option("--cloth", o->cloth, "cloth.json to generate (default: the built-in plain weave)")
          ->check(file_name)
          ->excludes(o->input.grid_option);
      sub.add_option("--axes", o->axes, "Beam axes, comma separated: x, y, z, optionally signed (-z)")
          ->capture_default_str();
      sub.add_option("--rays", o->rays,
                     "Rays per voxel column: 1 (validate's beams run along axes, where every ray of a column "
                     "crosses the same voxels; jittered oblique beams: weft measure --direction)")
          ->capture_default_str();
      sub.add_option("--window", o->window,
                     "Scale L of the statistics (window of Eq. 19-20, block of the local fields): yarn (the yarn "
                     "diameter from the grid's provenance, else measured), yarn-measured, corr (fibre-scale "
                     "correlation length; depends on the voxel), extent, or a length")
          ->capture_default_str();
      sub.add_flag("--no-plot", o->no_plot, "Do not render transmittance.png and cloth.png");
      sub.add_flag("--no-vti", o->no_vti,
                   "Do not write cloth.vti (the grid's active box as dense image data: 0.8 GB and half the CPU of a "
                   "run on a 23 M-voxel knit)");
      sub.add_option("--seed", o->seed,
                     "Seed of the generated cloth (no --grid or --cloth), of --sweep's and of --corpus's cloths")
          ->capture_default_str();
      sub.add_option("--method", o->method, "Beam tracing: auto | streaming | per-ray | openvdb")
          ->capture_default_str();
      sub.add_option("--out", o->out, "Output folder")->capture_default_str();
      sub.add_flag("--scenes", o->scenes,
                   "Also write OUT/scenes/ for `weft render`: grid.json (the fine grid), local_gamma.json with "
                   "local_fields.vdb (blocks of L^3), and slab_<model>.json, a homogeneous slab per predicted law "
                   "along the cloth's normal; all with the same camera and lights");
      auto* sweep =
          sub.add_flag("--sweep", o->sweep,
                       "Accuracy vs time instead of the validation: reference beams, 1/4 and 1/16 of the rays, and "
                       "exponential and gamma models on grids downsampled 2, 4, 8, 16 times (accuracy_time.csv/.png)");
      auto* corpus = sub.add_flag("--corpus", o->corpus,
                                  "The corpus study: every woven pattern and the knit x cotton, polyester, wool x "
                                  "voxel sizes 10 and 20 um, default sigma and window (corpus.csv, corpus.png)");
      corpus->excludes(sweep)->excludes(o->input.grid_option);
      sub.add_option("--cases", o->cases,
                     "With --corpus: only the cases whose name contains one of these comma-separated parts (names "
                     "like plain-cotton-20um; e.g. --cases 20um or --cases twill,satin)")
          ->delimiter(',');
      sub.add_flag("--quick", o->quick,
                   "With --sweep: one timing run instead of the median of 3; with --corpus: patterns plain and "
                   "stockinette, cotton only, 20 um");
      sub.add_flag("--resume", o->resume,
                   "With --sweep or --corpus: keep the units (sweep points, cases) a killed run finished "
                   "(OUT/units/) and compute only the rest; same options required");
      sub.add_flag("--fibres", o->fibres,
                   "Also measure each axis through the fibres the grid was generated from (opaque, same rays): "
                   "T_fibre and the voxelization error T_gt - T_fibre in report.json (docs/validate.md)");
      sub.add_option("--models", o->models,
                     "Models to compute beside the exponential baseline: all, predicted (the prediction alone, "
                     "local-gamma-two-scale: the block statistics only, the cheapest run), or names separated by "
                     "commas: gamma, empirical, gap-gamma, across-beam, local-exponential, local-gamma, "
                     "local-gamma-renewal, local-gamma-two-scale, isotropic, least-squares")
          ->capture_default_str();
      return [o, &sub](const Context& ctx) -> int {
        const auto t_start = std::chrono::steady_clock::now();
        if (o->fibres && (o->sweep || o->corpus))
          usage_fail("--fibres goes with a validation, not --sweep or --corpus");
        usage_needs(sub, {"--quick", "--resume"}, o->sweep || o->corpus, "--sweep or --corpus");
        usage_needs(sub, {"--cases"}, o->corpus, "--corpus");
        // The seed draws the default cloth, the sweep's and the corpus's cloths; a given grid or
        // cloth.json (which holds its own seed) and validate's axis beams draw nothing.
        usage_needs(sub, {"--seed"}, o->sweep || o->corpus || (o->input.grid.empty() && o->cloth.empty()),
                    "a cloth to generate (no --grid or --cloth), --sweep or --corpus");
        usage_needs(sub, {"--models"}, !o->corpus && !o->sweep, "a validation, not --sweep or --corpus");
        if (o->scenes && (o->sweep || o->corpus))
          usage_fail("--scenes goes with a validation, not --sweep or --corpus");
        if (o->scenes && o->input.extinction()) usage_fail("--scenes needs a concentration grid (a cloth)");
        json timings = json::object();
        // Everything is checked and computed before the output folder is touched. Every beam of
        // validate (also of --sweep and --corpus) runs along an axis: --rays N > 1 is refused, the
        // rule Python shares.
        as_usage([&] { volume::check_rays_per_column({{0.0, 0.0, 1.0}}, o->rays, false, FrontEnd::cli); });
        check_grid_input(o->input);
        as_usage([&] { fit::check_scale_text(o->window, "--window"); });
        if (o->input.extinction() && o->input.grid.empty())
          usage_fail("--values extinction needs --grid (a cloth grid holds concentrations)");
        // --sweep and --corpus are spread over MPI ranks; the validation runs on rank 0.
        if (o->corpus) return run_corpus({o->out, o->no_plot, o->quick, o->resume, o->seed, o->window, o->cases}, ctx);
        if (!o->sweep && !dist::is_root()) return 0;
        fit::ValidationSpec spec;
        spec.directions = as_usage([&] { return fit::parse_axes(o->axes); });
        spec.models = as_usage([&] { return fit::ModelSelection::parse(o->models); });
        spec.rays_per_column = o->rays;
        spec.seed = o->seed;
        spec.method = as_usage([&] { return volume::parse_beam_method(o->method); });

        json input;
        volume::Grid grid;
        volume::Provenance provenance;
        volume::SigmaChoice sigma;
        std::string title;
        if (!o->input.grid.empty()) {
          const auto t0 = std::chrono::steady_clock::now();
          LoadedGrid loaded = load_grid_input(o->input);
          timings["load_grid"] = seconds_since(t0);
          grid = loaded.grid;
          provenance = loaded.provenance;
          sigma = loaded.sigma;
          input = {{"source", "grid"}, {"file", fs::absolute(o->input.grid).string()}, {"grid_name", grid.name()}};
          title = grid_title(o->input, grid);
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
          // The same provenance a saved cloth.vdb carries: `--grid cloth.vdb` gives the same σ and L.
          provenance = volume::read_provenance(grid);
          sigma = resolve_sigma(o->input, provenance, "cloth");
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
        spec.sigma = sigma.sigma;
        if (o->scenes && !provenance.sigma)
          fail(
              "--scenes: the grid has no sigma in its metadata (weft:sigma_per_concentration); cloth scenes are "
              "made for grids of weft gen");
        const std::string units = provenance.units.empty() ? "length units" : provenance.units;
        if (o->sweep)
          return run_sweep({o->out, o->no_plot, o->quick, o->resume, o->axes}, ctx, grid, spec, title, input, timings,
                           t_start);
        auto t0 = std::chrono::steady_clock::now();
        const fit::StatisticsScale scale = fit::resolve_scale(o->window, grid, provenance, ctx.progress);
        timings["scale"] = seconds_since(t0);
        spec.scale = scale.length;
        const fit::ScaleUse scale_used = fit::scale_use(scale, grid, spec.models.needs_blocks());
        for (const auto& note : scale_used.notes) ctx.warn(note);
        const fit::Validation v = fit::validate(grid, spec, ctx.progress);
        for (const auto& a : v.axes) {
          if (!a.least_squares_note.empty()) ctx.warn(fmt::format("beam {}: {}", a.label, a.least_squares_note));
        }
        std::optional<FibreCheck> fibre_check;  // before any output: a grid without its fibres writes nothing
        if (o->fibres)
          fibre_check =
              check_against_fibres(grid, v, spec.seed, o->input.grid.empty() ? "cloth" : o->input.grid, ctx.progress);

        // Texts first (in memory), then files.
        const auto box = grid.active_bbox();
        input["values"] = o->input.values;
        input["voxel_size"] = grid.voxel_size();
        input["active_voxels"] = grid.active_voxel_count();
        input["grid_memory_bytes"] = grid.memory_bytes();  // OpenVDB memUsage(), the floor of any run on it
        input["bbox_index"] = {{"min", box.min}, {"max", box.max}};
        input["origin"] = grid.origin();
        json report = json::parse(fit::validation_json(v));
        report["weft"] = "validate";
        report["ranks"] = ctx.ranks();
        report["threads"] = ctx.threads();
        report["units"] = fmt::format("lengths in {}; sigma in 1/{}", units, units);
        report["input"] = input;
        report["sigma_source"] = sigma.source;
        report["window"] = {{"rule", scale.rule},
                            {"source", scale.source},
                            {"length", scale.length},
                            {"length_used", scale_used.length}};
        report["window_meaning"] =
            "scale L of every predictive model: window of the window statistics (all positions along every column, "
            "stride one voxel), cell of the across-beam groups and block of the local fields";
        if (fibre_check) report["fibre_ground_truth"] = fibre_check->report;
        report["rays_per_column"] = spec.rays_per_column;
        report["seed"] = spec.seed;
        if (v.has_isotropic) timings["isotropic_stats"] = v.isotropic_seconds;
        for (const auto& a : v.axes) timings[fmt::format("beam_{}", a.label)] = a.beam_seconds;
        const std::string csv = curves_csv(v, fibre_check ? &fibre_check->curves : nullptr);

        const fs::path out = o->out;
        // Its files appear together, or the folder stays as it was (docs/robustness.md "Output
        // folders of failed runs").
        FolderRollback written(out);
        t0 = std::chrono::steady_clock::now();
        WrittenFiles outputs;
        json skipped = json::object();
        write_text_atomically(out / "curves.csv", csv);
        outputs.add(out / "curves.csv", "ground truth and every model per axis");
        if (o->input.grid.empty()) {
          // The generated grid, so `weft measure` and `weft fit` can run the stages alone on it.
          grid.save(out / "cloth.vdb");
          outputs.add(out / "cloth.vdb", "generated grid");
        }
        // The .vti is optional: a grid it cannot hold is skipped with the reason; a failed write
        // (a full disk) fails the run like any other output.
        if (o->no_vti) {
          skipped["cloth.vti"] = "--no-vti";
        } else if (const std::string why = viz::vti_refusal(grid); !why.empty()) {
          skipped["cloth.vti"] = fmt::format("{}: {}", (out / "cloth.vti").string(), why);
        } else {
          viz::write_vti(grid, out / "cloth.vti");
          outputs.add(out / "cloth.vti", "grid for ParaView");
        }
        if (o->scenes) {
          // The fine grid as the scenes name it: the generated cloth.vdb beside scenes/, or the input.
          const fs::path vdb = o->input.grid.empty() ? out / "cloth.vdb" : fs::path(o->input.grid);
          const std::string in_scene =
              o->input.grid.empty() ? std::string("../cloth.vdb") : fs::absolute(o->input.grid).string();
          const study::ModelScenes scenes =
              study::write_model_scenes(v, grid, vdb, in_scene, out / "scenes", ctx.progress);
          for (const auto& [path, what] : scenes.written) outputs.add(path, what);
          for (const auto& note : scenes.notes) skipped[note.substr(0, note.find(' '))] = note;
        }
        timings["write_data"] = seconds_since(t0);
        // report.json goes out before the plots too: a renderer that dies takes nothing with it.
        report["outputs"] = outputs.to_json(out);
        report["outputs_skipped"] = skipped;
        report["timings_seconds"] = timings;
        write_text_atomically(out / "report.json", report.dump(2) + "\n");
        if (o->no_plot) {
          skipped["transmittance.png"] = "--no-plot";
          skipped["cloth.png"] = "--no-plot";
        } else {
          t0 = std::chrono::steady_clock::now();
          std::string why;
          if (!viz::ensure_display(&why)) {
            skipped["transmittance.png"] = fmt::format("not rendered: {}", why);
            skipped["cloth.png"] = fmt::format("not rendered: {}", why);
          } else {
            const auto chart = save_transmittance_figure(v, title, units, out / "transmittance.png",
                                                         fibre_check ? &fibre_check->curves : nullptr);
            if (chart.written)
              outputs.add(out / "transmittance.png", "T(t) per axis, every model");
            else
              skipped["transmittance.png"] = fmt::format("not rendered: {}", chart.reason);
            viz::VolumeView view;
            view.title = title;
            for (const auto& a : v.axes)
              view.arrows.push_back({a.direction, axis_color(a.direction), fmt::format("beam {}", a.label)});
            const auto pic = viz::save_volume_png(grid, view, out / "cloth.png");
            if (pic.written)
              outputs.add(out / "cloth.png", "3D view with the beams");
            else
              skipped["cloth.png"] = fmt::format("not rendered: {}", pic.reason);
          }
          timings["plots"] = seconds_since(t0);
        }
        timings["total"] = seconds_since(t_start);
        // report.json lists every other file (its own size would depend on its timings' digits).
        report["outputs"] = outputs.to_json(out);
        report["outputs_skipped"] = skipped;
        report["timings_seconds"] = timings;
        write_text_atomically(out / "report.json", report.dump(2) + "\n");
        outputs.add(out / "report.json", "report");
        written.keep();

        ctx.say(fmt::format("weft validate: {}; {} active voxels of {:.4g} {}", title, grid.active_voxel_count(),
                            grid.voxel_size(), units));
        ctx.say(fmt::format("sigma = {:.6g}/{} ({})", spec.sigma, units, sigma.source));
        std::string lengths;
        for (const auto& a : v.axes) lengths += fmt::format(" {}={:.4g}", a.label, a.scale);
        ctx.say(fmt::format("scale L ={} {} ({})", lengths, units, scale.source));
        ctx.say(fmt::format("active: beams {}, {}models {} ({} curves with the exponential baseline){}", o->axes,
                            spec.models.needs_windows() ? "window statistics, " : "", spec.models.text(),
                            v.axes.empty() ? 0 : v.axes.front().models.size(), o->no_plot ? "; plots off" : "; plots"));
        for (const auto& line : summary_table(v)) ctx.say(line);
        if (fibre_check) {
          for (const auto& line : fibre_check->summary) ctx.say(line);
        }
        std::string stages;
        for (auto it = timings.begin(); it != timings.end(); ++it) {
          stages += fmt::format("{}{} {:.2f}s", stages.empty() ? "" : ", ", it.key(), it.value().get<double>());
        }
        ctx.say(fmt::format("timings: {}", stages));
        for (auto it = skipped.begin(); it != skipped.end(); ++it) {
          const std::string why = it.value().get<std::string>();
          if (why != "--no-plot" && why != "--no-vti")
            fmt::print(stderr, "weft validate: note: {} {}\n", it.key(), why);
        }
        outputs.say(ctx);
        return 0;
      };
    },
    /*distributed=*/true}};

}  // namespace
}  // namespace weft::app
