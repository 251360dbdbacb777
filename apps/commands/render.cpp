// `weft render`: volumetric path tracing of a JSON scene (docs/render.md, docs/scene-format.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "data_gen/cloth/cloth.h"
#include "render_matrix.h"
#include "render_study.h"
#include "usage.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/parse_number.h"
#include "weft/core/paths.h"
#include "weft/dist/distributed.h"
#include "weft/fit/scale.h"
#include "weft/render/builtin_scenes.h"
#include "weft/render/cloth_scene.h"
#include "weft/render/contact_sheet.h"
#include "weft/render/convergence.h"
#include "weft/render/render.h"
#include "weft/render/scene_checks.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/viz/chart.h"
#include "written_files.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;

struct RenderCliOptions {
  std::string scene;
  std::string output;
  std::string out_dir;  ///< --out DIR: <DIR>/<scene>.exr and .png (the convention of every command)
  int spp = 0;
  double time_budget = 0.0;
  std::optional<std::uint64_t> seed;
  std::string convergence;
  int reference_spp = 0;
  bool study = false;
  double study_time = 0.0;
  int study_spp = 0;
  std::vector<int> study_factors;
  std::string study_window = study::StudySpec{}.scale;
  std::vector<std::string> study_memory;
  std::vector<std::string> study_albedo;  ///< {"fit"} or {"N:k", …}
  std::vector<std::string> study_components;
  MatrixCliOptions matrix;  ///< the matrix's own options (--study with no scene)
  std::string lighting;
  double tilt = -1.0;
  bool quick = false;
  bool list = false;
  bool print_scene = false;
  double exposure = 1.0;
};

/// spp of the images the contact sheet shows (supplement Figs. S.7–S.8), those ≤ the run's spp.
constexpr int kSheetSpp[] = {2, 8, 64, 128, 512};
/// --quick: the series' spp (its film: render::kQuickFilmSide).
constexpr int kQuickSpp = 128;

/// A path that exists is a scene file; otherwise the name of a built-in scene.
render::SceneDesc resolve_scene(const std::string& name, std::string& label) {
  if (fs::exists(name) || name.find('/') != std::string::npos || name.ends_with(".json")) {
    label = fs::path(name).stem().string();
    return render::load_scene(name);
  }
  label = name;
  return render::parse_scene(render::builtin_scene(name), "built-in scene '" + name + "'", fs::current_path());
}

/// The default cloth (`weft gen` with no options) as a grid, generated once and kept in the
/// temporary folder under a name that hashes its spec, so a changed generator makes a new one.
fs::path default_cloth_grid(const Context& ctx) {
  const cloth::ClothSpec spec = cloth::resolve(cloth::default_cloth_spec());
  const std::string text = cloth::cloth_spec_json(spec);
  const fs::path dir = fs::temp_directory_path() / "weft-cache";
  fs::path vdb = dir / fmt::format("default_cloth_{:016x}.vdb", std::hash<std::string>{}(text));  // moved out
  if (fs::exists(vdb)) return vdb;
  ctx.say(fmt::format("generating the default cloth once ({})", vdb.string()));
  ensure_directory(dir);
  cloth::build_cloth(spec, ctx.progress).grid.save(vdb);
  return vdb;
}

/// `--out DIR` writes <DIR>/<scene>.exr; `-o` names the EXR or the PNG (in any case: X.EXR is an
/// EXR, written under that name); the other is written beside it with the other extension. Anything
/// else is refused rather than silently renamed.
void output_paths(const RenderCliOptions& o, const std::string& label, fs::path& exr, fs::path& png) {
  const std::string& output = o.output;
  const fs::path given = !o.out_dir.empty() ? fs::path(o.out_dir) / (label + ".exr")
                         : output.empty()   ? fs::path(label + ".exr")
                                            : fs::path(output);
  const std::string ext = lower_extension(given);
  if (ext != ".exr" && ext != ".png")
    usage_fail(
        "-o: '{}' must end in .exr or .png, in any case (both are written, the other one beside it; --out DIR names "
        "a folder)",
        output);
  exr = given;
  png = given;
  if (ext == ".exr")
    png.replace_extension(".png");
  else
    exr.replace_extension(".exr");
}

fs::path beside(const fs::path& exr, const std::string& suffix) {
  fs::path p = exr;
  p.replace_extension(suffix);
  return p;
}

/// The convergence study's outputs (docs/render.md §6).
struct Convergence {
  std::optional<render::Image> reference;
  std::string csv = "spp,seconds,rmse,rmse_corrected\n";
  std::vector<double> spp, seconds, error;
  std::vector<render::Image> sheet;
  std::vector<int> sheet_spp;
};

int run(const RenderCliOptions& o, const CLI::App& sub, const Context& ctx) {
  if (o.list) {
    for (const auto& name : render::builtin_scene_names()) fmt::print("{}\n", name);
    return 0;
  }
  std::string label;
  // `weft render ""` is a scene name left empty by mistake, not the default cloth.
  if (o.scene.empty() && sub.get_option("scene")->count() > 0)
    usage_fail("scene: must name a scene file or a built-in scene, got an empty value");
  const bool default_scene = o.scene.empty();
  render::SceneDesc scene;
  usage_needs(sub, {"--lighting", "--tilt"}, default_scene, "the default cloth's scene (give no scene file)");
  // --study with no scene, --lighting or --tilt: the study matrix, which makes its own scenes.
  const bool matrix = o.study && default_scene && o.lighting.empty() && o.tilt < 0.0;
  usage_needs(sub,
              {"--study-time", "--study-spp", "--study-factors", "--study-window", "--study-memory", "--study-albedo",
               "--study-components"},
              o.study, "--study");
  usage_needs(sub,
              {"--study-cloths", "--study-lightings", "--study-tilts", "--study-film", "--study-yarns", "--resume"},
              matrix, "the study matrix (--study with no scene, --lighting or --tilt)");
  // The matrix fits its albedo factors per cloth on one set-up and writes its cases' PNGs at
  // exposure 1, the light set-ups being exposed by their own intensities (docs/render.md §6e):
  // these two would do nothing there.
  usage_needs(sub, {"--study-albedo", "--exposure"}, !matrix,
              "a scene, --lighting or --tilt (the study matrix fits its albedo factors per cloth and writes its "
              "PNGs at exposure 1)");
  if (default_scene && !matrix) {
    label = render::kDefaultScene;
    render::ClothView view;
    if (!o.lighting.empty()) view.lighting = as_usage([&] { return render::cloth_lighting(o.lighting); });
    if (o.tilt >= 0.0) view.tilt_degrees = o.tilt;
    scene = render::cloth_scene(default_cloth_grid(ctx), view);
  } else if (!matrix) {
    scene = resolve_scene(o.scene, label);
  } else {
    label = "render_study";
  }
  for (const std::string& w : render::scene_warnings(scene)) ctx.warn(w);
  if (o.quick && !matrix) render::shrink_film(scene.camera, render::kQuickFilmSide);  // same view
  if (o.print_scene) {
    if (dist::is_root()) fmt::print("{}", render::scene_to_json(scene));
    return 0;
  }
  fs::path exr;
  fs::path png;
  output_paths(o, label, exr, png);
  const fs::path folder = exr.has_parent_path() ? exr.parent_path() : fs::path(".");
  // -o FILE writes into an existing folder; --out DIR is created (after the checks, before the
  // first file) like every command's --out.
  if (o.out_dir.empty() && !fs::is_directory(folder)) fail("output folder '{}' does not exist", folder.string());

  WrittenFiles files;
  render::RenderOptions options;
  if (o.spp > 0) options.spp = o.spp;
  options.seed = o.seed;
  options.time_budget_seconds = o.time_budget;
  usage_needs(sub, {"--reference-spp"}, o.convergence == "auto" || o.study, "--convergence auto or --study");
  if (!std::isfinite(o.study_time))
    usage_fail("--study-time: must be a finite number of seconds, got {}", o.study_time);
  if (o.study) {
    if (!o.convergence.empty()) usage_fail("--study and --convergence are separate runs: give one");
    if (o.spp > 0 || o.time_budget > 0.0)
      usage_fail("--study renders each candidate by --study-time or --study-spp, not --spp or --time-budget");
    study::StudySpec spec = study::default_study_spec(o.quick);
    if (!o.study_factors.empty()) {
      std::vector<int> sorted = o.study_factors;
      std::sort(sorted.begin(), sorted.end());
      if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
        usage_fail("--study-factors: a factor is given twice ({})", fmt::join(o.study_factors, ","));
      spec.factors = sorted;
      spec.factors_given = true;
    }
    // Checked even when given empty: `--study-window ""` is a mistake, not the default.
    as_usage([&] { fit::check_scale_text(o.study_window, "--study-window"); });
    spec.scale = o.study_window;
    if (!o.study_memory.empty()) {
      spec.memory_rules.clear();
      for (const std::string& name : o.study_memory) {
        const auto rule = transmittance::parse_memory_rule(name);
        if (!rule)
          usage_fail("--study-memory: unknown memory rule '{}' (segment, renewal, optical-depth, carried)", name);
        spec.memory_rules.push_back(*rule);
      }
    }
    spec.components = o.study_components;
    const bool fit_albedo = o.study_albedo == std::vector<std::string>{"fit"};
    spec.albedo_fitted = fit_albedo;
    if (!o.study_albedo.empty() && !fit_albedo) {
      for (const std::string& item : o.study_albedo) {
        const auto colon = item.find(':');
        const auto f = colon == std::string::npos ? std::nullopt : parse_option_number(item.substr(0, colon));
        const auto k = colon == std::string::npos ? std::nullopt : parse_option_number(item.substr(colon + 1));
        if (!f || !k || *f != std::floor(*f) || !std::isfinite(*k))
          usage_fail("--study-albedo: '{}' is not FACTOR:K (e.g. 4:1.08), nor 'fit'", item);
        spec.albedo_factors.emplace_back(static_cast<int>(*f), *k);
      }
    }
    if (matrix) {
      MatrixStudyChoices given;
      given.factors = !o.study_factors.empty();
      given.memory = !o.study_memory.empty();
      given.spp = o.study_spp;
      given.reference_spp = o.reference_spp;
      given.seed = o.seed;
      given.quick = o.quick;
      given.study_time = o.study_time > 0.0;
      given.output_file = !o.output.empty();
      given.out_dir = o.out_dir;
      run_render_matrix_command(spec, o.matrix, given, ctx, files);
      files.say(ctx);
      return 0;
    }
    if (o.study_time > 0.0) spec.seconds = o.study_time;
    spec.spp = o.study_spp;
    if (o.reference_spp > 0) spec.reference_spp = o.reference_spp;
    spec.seed = o.seed.value_or(scene.integrator.seed);
    spec.work_dir = "(beside the output)";  // the app sets it; checked here for the other fields
    as_usage([&] { study::check_study_spec(spec); });
    study::check_study_scene(scene, spec);  // refuse a scene without a grid before creating anything
    // The study's folder (--out DIR, created here, or -o FILE's) either gets every file of a
    // finished study or is left as it was (docs/robustness.md "Output folders of failed runs").
    FolderRollback out_folder(folder, dist::is_root());
    run_render_study(scene, spec, label, exr, o.exposure, ctx, files, fit_albedo);
    out_folder.keep();
    files.say(ctx);
    return 0;
  }

  // Every file the scene names is read and every medium built here, once, before anything is
  // written; the reference and the image render this same world.
  const render::World world = render::build_world(scene);
  for (const std::string& w : render::world_warnings(world)) ctx.warn(w);
  Convergence conv;
  // Made before the first file (rank 0 writes): the run's files appear together, or the folder
  // stays as it was (docs/robustness.md "Output folders of failed runs").
  std::optional<FolderRollback> written;
  if (!o.convergence.empty()) {
    // The series runs to 512 spp (128 with --quick) unless --spp says otherwise.
    if (o.spp == 0) options.spp = o.quick ? kQuickSpp : 512;
    if (o.convergence == "auto") {
      // The reference: 16× the series' samples (8× with --quick) with an independent seed, so its
      // noise is independent of the series' and can be subtracted (rmse_corrected).
      render::RenderOptions ref;
      ref.spp = o.reference_spp > 0 ? o.reference_spp : (o.quick ? 8 : 16) * *options.spp;
      ref.seed = options.seed.value_or(scene.integrator.seed) + 0x9E3779B97F4A7C15ULL;
      if (*ref.spp < *options.spp)
        ctx.warn(
            fmt::format("the reference has fewer samples ({} spp) than the series' last image ({} spp): the "
                        "RMSE there is mostly the reference's own noise",
                        *ref.spp, *options.spp));
      ctx.say(fmt::format("rendering the reference at {} spp", *ref.spp));
      conv.reference = render::render(world, ref, ctx.progress).image;
      if (dist::is_root()) {
        written.emplace(folder);
        render::write_exr(beside(exr, ".reference.exr"), *conv.reference);
        files.add(beside(exr, ".reference.exr"), "reference, linear");
      }
    } else {
      conv.reference = render::read_exr(o.convergence);
      render::check_reference(*conv.reference, o.convergence);
    }
    const render::Image& reference = *conv.reference;
    if (reference.width != scene.camera.width || reference.height != scene.camera.height)
      fail("reference '{}' is {}x{} but the scene renders {}x{}", o.convergence, reference.width, reference.height,
           scene.camera.width, scene.camera.height);
    options.on_pass = [&](int spp_done, double seconds, const render::Image& image) {
      if (std::find(std::begin(kSheetSpp), std::end(kSheetSpp), spp_done) != std::end(kSheetSpp)) {
        conv.sheet.push_back(image);
        conv.sheet_spp.push_back(spp_done);
      }
      // Only at powers of two: RMSE needs a full image, and log axes want even spacing.
      if ((spp_done & (spp_done - 1)) != 0) return;
      const double raw = render::rmse(image, reference);
      const double corrected = render::rmse_against_noisy_reference(image, reference);
      conv.csv += fmt::format("{},{:.6g},{:.8g},{:.8g}\n", spp_done, seconds, raw, corrected);
      conv.spp.push_back(spp_done);
      conv.seconds.push_back(seconds);
      conv.error.push_back(corrected);
    };
  }

  const render::RenderResult result = render::render(world, options, ctx.progress);
  if (!dist::is_root()) return 0;  // the tiles were gathered on rank 0, which writes
  if (!written) written.emplace(folder);
  render::write_exr_and_png(exr, png, result.image, o.exposure);
  files.add(exr, "linear");
  files.add(png, "sRGB");

  const auto& s = result.stats;
  if (default_scene) ctx.say(fmt::format("rendered the default scene '{}' (no scene given)", label));
  ctx.say(fmt::format("features: {}; integrator: {}", fmt::join(s.features.names(), ", "), s.integrator));
  ctx.say(fmt::format("{}x{} at {} spp in {:.2f} s: {:.3g} samples/s, {:.3g} rays/s; {} rank(s) x {} thread(s)",
                      result.image.width, result.image.height, s.spp, s.seconds,
                      static_cast<double>(s.paths) / s.seconds, static_cast<double>(s.rays) / s.seconds, ctx.ranks(),
                      ctx.threads()));
  if (s.medium_cells > 0)
    ctx.say(fmt::format("grid media: {:.3g} cells crossed/s, {:.3g} density lookups/s ({:.3g} and {:.3g} per sample)",
                        static_cast<double>(s.medium_cells) / s.seconds,
                        static_cast<double>(s.medium_lookups) / s.seconds,
                        static_cast<double>(s.medium_cells) / static_cast<double>(s.paths),
                        static_cast<double>(s.medium_lookups) / static_cast<double>(s.paths)));
  if (s.invalid_samples > 0) ctx.say(fmt::format("warning: {} NaN/inf samples were dropped", s.invalid_samples));

  if (conv.reference) {
    // The rate: fit log RMSE against log spp and log seconds over the points from 2 spp on
    // (1 spp is dominated by the first bounce's fireflies); Monte Carlo gives slope −1/2.
    std::vector<double> fit_spp, fit_seconds, fit_error;
    for (std::size_t i = 0; i < conv.spp.size(); ++i) {
      if (conv.spp[i] < 2) continue;
      fit_spp.push_back(conv.spp[i]);
      fit_seconds.push_back(conv.seconds[i]);
      fit_error.push_back(conv.error[i]);
    }
    // A fit needs two points with error > 0 (an exact render has none): then no slope is reported.
    std::optional<render::LogLogFit> by_spp;
    std::optional<render::LogLogFit> by_time;
    try {
      by_spp = render::fit_log_log(fit_spp, fit_error);
      by_time = render::fit_log_log(fit_seconds, fit_error);
    } catch (const Error& e) {
      ctx.say(fmt::format("no convergence slope: {}", e.what()));
    }
    const fs::path csv_path = beside(exr, ".convergence.csv");
    write_text_atomically(csv_path, conv.csv);
    files.add(csv_path, "RMSE vs spp and seconds");
    nlohmann::json summary = {
        {"scene", label},
        {"width", scene.camera.width},
        {"height", scene.camera.height},
        {"spp", s.spp},
        {"reference", o.convergence == "auto" ? beside(exr, ".reference.exr").string() : o.convergence},
        {"reference_spp", conv.reference->spp},
        {"ranks", ctx.ranks()},
        {"threads", ctx.threads()},
        {"contact_sheet_spp", conv.sheet_spp}};
    if (by_spp && by_time) {
      summary["fit_points"] = by_spp->points;
      summary["slope_vs_spp"] = by_spp->slope;
      summary["slope_vs_spp_stderr"] = by_spp->slope_stderr;
      summary["slope_vs_seconds"] = by_time->slope;
      summary["slope_vs_seconds_stderr"] = by_time->slope_stderr;
      ctx.say(
          fmt::format("RMSE slope vs spp {:.3f} (+-{:.3f}), vs time {:.3f} (+-{:.3f}) over {} points from 2 spp; "
                      "the Monte Carlo rate is -0.5",
                      by_spp->slope, by_spp->slope_stderr, by_time->slope, by_time->slope_stderr, by_spp->points));
    }
    const fs::path json_path = beside(exr, ".convergence.json");
    write_text_atomically(json_path, summary.dump(2) + "\n");
    files.add(json_path, "convergence summary");
    const fs::path sheet_path = beside(exr, ".contact.png");
    if (!conv.sheet.empty()) {
      std::vector<render::SheetTile> tiles;
      for (std::size_t i = 0; i < conv.sheet.size(); ++i)
        tiles.push_back({conv.sheet[i], fmt::format("{} spp", conv.sheet_spp[i]), o.exposure});
      render::write_contact_sheet_png(sheet_path, tiles);
      files.add(sheet_path, fmt::format("contact sheet, left to right: {} spp", fmt::join(conv.sheet_spp, ", ")));
    }
    const fs::path chart_path = beside(exr, ".convergence.png");
    // Two panels: samples per pixel and seconds are different units, so each gets its own axis.
    viz::Chart by_spp_chart;
    by_spp_chart.title = "RMSE vs samples per pixel";
    by_spp_chart.x_label = "samples per pixel";
    by_spp_chart.y_label = "RMSE";
    by_spp_chart.log_x = true;
    by_spp_chart.log_y = true;
    by_spp_chart.width = 700;
    by_spp_chart.height = 560;
    viz::Chart by_time_chart = by_spp_chart;
    by_time_chart.title = "RMSE vs render time";
    by_time_chart.x_label = "seconds";
    by_spp_chart.series = {
        viz::Series{"RMSE", conv.spp, conv.error, {31, 119, 180}, viz::LineStyle::solid, 2.0f, viz::Marker::circle}};
    by_time_chart.series = {
        viz::Series{"RMSE", conv.seconds, conv.error, {214, 39, 40}, viz::LineStyle::solid, 2.0f, viz::Marker::circle}};
    const viz::RenderOutcome outcome =
        viz::save_chart_grid_png({by_spp_chart, by_time_chart}, 2, chart_path, "Convergence of " + label);
    if (outcome.written) {
      files.add(chart_path, "convergence chart");
    } else {
      ctx.say(fmt::format("no chart {}: {}", chart_path.string(), outcome.reason));
    }
  }
  written->keep();
  files.say(ctx);
  return 0;
}

const Registrar kRender{Command{
    "render", "Render a scene with non-exponential media by volumetric path tracing", 50,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<RenderCliOptions>();
      sub.add_option(
          "scene", o->scene,
          "Scene file (.json, docs/scene-format.md, e.g. the scene.json `weft gen` writes) or built-in scene name; "
          "default: the default cloth of `weft gen` as a grid medium");
      auto* output = sub.add_option("-o,--output", o->output,
                                    "Image path ending in .exr or .png in an existing folder; both are written, the "
                                    "other beside it (default: ./<scene>.exr)");
      sub.add_option("--out", o->out_dir,
                     "Output folder (created if missing), like every weft command: writes <scene>.exr, "
                     "<scene>.png and the --convergence files inside")
          ->excludes(output);
      sub.add_option("--spp", o->spp, "Samples per pixel (default: the scene's)")
          ->check(CLI::Range(1, render::kMaxSpp));
      sub.add_option("--time-budget", o->time_budget,
                     "Stop after the sample pass that ends past this many seconds (0 = no limit)")
          ->check(in_range(0.0, 1e9));
      sub.add_option("--seed", o->seed, "Run seed (default: the scene's); same seed, same image for any --threads");
      sub.add_option("--convergence", o->convergence,
                     "Reference EXR, or 'auto' to render one at --reference-spp: write RMSE vs spp and time "
                     "(<output>.convergence.csv/.json/.png, fitted log-log slopes) and a contact sheet of the "
                     "2, 8, 64, 128, 512 spp images (<output>.contact.png); the series runs to 512 spp unless --spp");
      sub.add_option(
             "--reference-spp", o->reference_spp,
             "spp of the reference rendered by --convergence auto (default: 16x the series' spp, 8x with --quick) or "
             "by --study (default 1024, 256 with --quick)")
          ->check(CLI::Range(1, render::kMaxSpp));
      sub.add_flag("--study", o->study,
                   "Accuracy vs time (docs/render.md 6c): the scene's grid medium (default: the default cloth) "
                   "rendered to --reference-spp as the reference, then the fine grid, the grid downsampled by "
                   "--study-factors (exponential per coarse voxel, and local gamma fields) and one gamma slab, each "
                   "at --study-time; writes <output>.study.csv/.curves.csv/.json/.png/.contact.png and "
                   "<output>.study/ (grids, fields, scenes, images); the main image is the reference");
      auto* study_time = sub.add_option("--study-time", o->study_time,
                                        "--study: wall seconds per candidate image (default 10, 1 with --quick); "
                                        "the spp reached is recorded")
                             ->check(in_range(study::kMinStudySeconds, study::kMaxStudySeconds));
      sub.add_option("--study-spp", o->study_spp,
                     "--study: every candidate at this spp instead of a time budget (deterministic: same bytes for "
                     "any --threads or ranks)")
          ->check(CLI::Range(1, study::kMaxStudySpp))
          ->excludes(study_time);
      sub.add_option("--study-factors", o->study_factors, "--study: coarsening factors (default 2,4,8,16)")
          ->delimiter(',')
          ->check(CLI::Range(2, 4096));
      sub.add_option("--study-window", o->study_window,
                     "--study: scale of the statistics behind the slab's law and the validation, as weft validate "
                     "--window (default yarn: the yarn diameter of the grid's provenance; a grid without it needs "
                     "a LENGTH or yarn-measured)");
      sub.add_option("--study-memory", o->study_memory,
                     "--study: memory rules of the local-gamma candidates, comma-separated (default optical-depth, "
                     "named local-gamma-Nx; the study matrix: optical-depth,segment; others are named "
                     "local-gamma-RULE-Nx: segment, renewal, carried; docs/render.md §5e)")
          ->delimiter(',');
      sub.add_option(
             "--study-albedo", o->study_albedo,
             "--study: albedo-corrected candidates (docs/render.md 6d): FACTOR:K,... (k_N fitted on another "
             "set-up) or 'fit' (fit k_N on this scene first and print them; in-sample); not with the study matrix, "
             "which fits them per cloth")
          ->delimiter(',');
      sub.add_option(
             "--study-components", o->study_components,
             "--study: also render the reference and these candidates with albedo 0 and with at most one "
             "scattering event, and split their bias into transmission, single and multiple scattering "
             "(docs/render.md 6e): candidate families without -Nx, comma-separated (exponential, "
             "local-gamma, local-gamma-segment, shadow-corrected, ...) or all; the fine grid is always split too")
          ->delimiter(',');
      add_matrix_options(sub, o->matrix);
      sub.add_option("--lighting", o->lighting,
                     "Default cloth only: light set-up key-and-back (default), back, front or grazing (docs/render.md "
                     "5c), e.g. to run --study under each");
      sub.add_option("--tilt", o->tilt,
                     "Default cloth only: camera angle off the cloth's normal in degrees (default 30; 0 looks straight "
                     "down)")
          ->check(cloth_tilt);
      sub.add_flag("--quick", o->quick,
                   "Small film (longest side 48 px); with --convergence, a 128 spp series; with --study, 1 s per "
                   "candidate and a 256 spp reference");
      sub.add_option("--exposure", o->exposure,
                     "Scale before sRGB conversion of the PNG (not with the study matrix: its PNGs are at 1)")
          ->check(positive);
      sub.add_flag("--list-scenes", o->list, "List the built-in scenes and exit");
      sub.add_flag("--print-scene", o->print_scene, "Print the scene as canonical JSON and exit");
      return [o, &sub](const Context& ctx) -> int { return run(*o, sub, ctx); };
    },
    /*distributed=*/true}};

}  // namespace
}  // namespace weft::app
