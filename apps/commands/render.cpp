// `weft render`: volumetric path tracing of a JSON scene (docs/render.md, docs/scene-format.md).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "command.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/render/builtin_scenes.h"
#include "weft/render/render.h"
#include "weft/viz/chart.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;

struct RenderCliOptions {
  std::string scene;
  std::string output;
  int spp = 0;
  double time_budget = 0.0;
  std::optional<std::uint64_t> seed;
  std::string convergence;
  bool list = false;
  bool print_scene = false;
  double exposure = 1.0;
};

/// A path that exists is a scene file; otherwise the name of a built-in scene.
render::SceneDesc resolve_scene(const std::string& name, std::string& label) {
  if (fs::exists(name) || name.find('/') != std::string::npos || name.ends_with(".json")) {
    label = fs::path(name).stem().string();
    return render::load_scene(name);
  }
  label = name;
  return render::parse_scene(render::builtin_scene(name), "built-in scene '" + name + "'", fs::current_path());
}

int run(const RenderCliOptions& o, const Context& ctx) {
  if (o.list) {
    for (const auto& name : render::builtin_scene_names()) fmt::print("{}\n", name);
    return 0;
  }
  std::string label;
  const bool default_scene = o.scene.empty();
  const render::SceneDesc scene = resolve_scene(default_scene ? render::kDefaultScene : o.scene, label);
  if (o.print_scene) {
    fmt::print("{}", render::scene_to_json(scene));
    return 0;
  }
  fs::path exr = o.output.empty() ? fs::path(label + ".exr") : fs::path(o.output);
  if (exr.extension() != ".exr") exr += ".exr";
  fs::path png = exr;
  png.replace_extension(".png");
  const fs::path folder = exr.has_parent_path() ? exr.parent_path() : fs::path(".");
  if (!fs::is_directory(folder)) fail("output folder '{}' does not exist", folder.string());

  render::RenderOptions options;
  if (o.spp > 0) options.spp = o.spp;
  options.seed = o.seed;
  options.time_budget_seconds = o.time_budget;

  std::optional<render::Image> reference;
  std::string csv = "spp,seconds,rmse\n";
  viz::Series by_spp{"RMSE vs spp", {}, {}, {31, 119, 180}};
  viz::Series by_time{"RMSE vs time", {}, {}, {214, 39, 40}};
  if (!o.convergence.empty()) {
    reference = render::read_exr(o.convergence);
    if (reference->width != scene.camera.width || reference->height != scene.camera.height)
      fail("reference '{}' is {}x{} but the scene renders {}x{}", o.convergence, reference->width, reference->height,
           scene.camera.width, scene.camera.height);
    options.on_pass = [&](int spp_done, double seconds, const render::Image& image) {
      // Only at powers of two: RMSE needs a full image, and log axes want even spacing.
      if ((spp_done & (spp_done - 1)) != 0) return;
      const double error = render::rmse(image, *reference);
      csv += fmt::format("{},{:.6g},{:.8g}\n", spp_done, seconds, error);
      by_spp.x.push_back(spp_done);
      by_spp.y.push_back(error);
      by_time.x.push_back(seconds);
      by_time.y.push_back(error);
    };
  }

  const render::RenderResult result = render::render(scene, options, ctx.progress);
  render::write_exr(exr, result.image);
  render::write_png(png, result.image, o.exposure);

  const auto& s = result.stats;
  if (default_scene) ctx.say(fmt::format("rendered the default scene '{}' (no scene given)", label));
  ctx.say(fmt::format("features: {}; integrator: {}", fmt::join(s.features.names(), ", "), s.integrator));
  ctx.say(fmt::format("{}x{} at {} spp in {:.2f} s: {:.3g} samples/s, {:.3g} rays/s", result.image.width,
                      result.image.height, s.spp, s.seconds, static_cast<double>(s.paths) / s.seconds,
                      static_cast<double>(s.rays) / s.seconds));
  if (s.invalid_samples > 0) ctx.say(fmt::format("warning: {} NaN/inf samples were dropped", s.invalid_samples));
  ctx.say(fmt::format("wrote {} (linear) and {} (sRGB)", exr.string(), png.string()));

  if (reference) {
    fs::path csv_path = exr;
    csv_path.replace_extension(".convergence.csv");
    write_text_atomically(csv_path, csv);
    fs::path chart_path = exr;
    chart_path.replace_extension(".convergence.png");
    viz::Chart chart;
    chart.title = "Convergence of " + label;
    chart.x_label = "samples per pixel (blue) / seconds (red)";
    chart.y_label = "RMSE";
    chart.log_x = true;
    chart.log_y = true;
    chart.series = {by_spp, by_time};
    const viz::RenderOutcome outcome = viz::save_chart_png(chart, chart_path);
    ctx.say(fmt::format("wrote {}{}", csv_path.string(),
                        outcome.written ? " and " + chart_path.string() : " (no chart: " + outcome.reason + ")"));
  }
  return 0;
}

const Registrar kRender{Command{
    "render", "Render a scene with non-exponential media by volumetric path tracing", 50, [](CLI::App& sub) -> Action {
      auto o = std::make_shared<RenderCliOptions>();
      sub.add_option("scene", o->scene,
                     "Scene file (.json, docs/scene-format.md) or built-in scene name; default: the cloth patch");
      sub.add_option("-o,--output", o->output, "Output EXR path; a PNG is written beside it (default: <scene>.exr)");
      sub.add_option("--spp", o->spp, "Samples per pixel (default: the scene's)")->check(CLI::Range(1, 1 << 24));
      sub.add_option("--time-budget", o->time_budget,
                     "Stop after the sample pass that ends past this many seconds (0 = no limit)")
          ->check(CLI::Range(0.0, 1e9));
      sub.add_option("--seed", o->seed, "Run seed (default: the scene's); same seed, same image for any --threads");
      sub.add_option("--convergence", o->convergence,
                     "Reference EXR: write RMSE vs spp and time as <output>.convergence.csv and .png");
      sub.add_option("--exposure", o->exposure, "Scale before sRGB conversion of the PNG")->check(CLI::PositiveNumber);
      sub.add_flag("--list-scenes", o->list, "List the built-in scenes and exit");
      sub.add_flag("--print-scene", o->print_scene, "Print the scene as canonical JSON and exit");
      return [o](const Context& ctx) -> int { return run(*o, ctx); };
    }}};

}  // namespace
}  // namespace weft::app
