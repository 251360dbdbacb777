// The volumetric path tracer (weft/render): a scene file, built-in name or JSON text -> image.
#include <algorithm>
#include <filesystem>
#include <string>

#include "common.h"
#include "weft/render/builtin_scenes.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/render/scene_checks.h"

namespace weft::python {
namespace {

namespace rd = weft::render;
namespace fs = std::filesystem;

rd::IntegratorChoice integrator_choice(const std::string& name) {
  if (name == "auto") return rd::IntegratorChoice::automatic;
  if (name == "surfaces") return rd::IntegratorChoice::surfaces;
  if (name == "exponential") return rd::IntegratorChoice::exponential;
  if (name == "general") return rd::IntegratorChoice::general;
  fail("render: integrator must be auto, surfaces, exponential or general, got '{}'", name);
}

py::array_t<float> image_array(const rd::Image& image, const std::vector<float>& values) {
  py::array_t<float> a({static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width), py::ssize_t{3}});
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

}  // namespace

void init_render(py::module_& m) {
  m.def(
      "_render",
      [](const std::string& kind, const std::string& text, const std::string& base_dir, std::optional<int> spp,
         std::optional<std::uint64_t> seed, const std::string& integrator, double time_budget, bool stats,
         const py::object& progress) -> py::object {
        rd::SceneDesc scene;
        if (kind == "file") {
          scene = rd::load_scene(text);
        } else if (kind == "builtin") {
          scene = rd::parse_scene(rd::builtin_scene(text), "built-in scene '" + text + "'", fs::current_path());
        } else {
          scene = rd::parse_scene(text, "scene dict", base_dir.empty() ? fs::current_path() : fs::path(base_dir));
        }
        // The CLI's scene warnings, as Python warnings (an error under warnings.simplefilter("error")).
        for (const std::string& w : rd::scene_warnings(scene)) {
          if (PyErr_WarnEx(PyExc_UserWarning, ("weft.render: " + w).c_str(), 2) != 0) throw py::error_already_set();
        }
        rd::RenderOptions options;
        if (spp) {
          if (*spp < 1) fail("render: spp must be >= 1, got {}", *spp);
          options.spp = *spp;
        }
        options.seed = seed;
        options.integrator = integrator_choice(integrator);
        options.time_budget_seconds = require_non_negative("render: time_budget", time_budget);
        // Progress is reported per tile and pass: at least 32 sample passes (a time budget already
        // gives passes of 1 spp) keep Ctrl-C and a raising callback prompt (docs/python.md
        // "Interrupting a call"); the image does not depend on the passes (render.h: sample s of
        // pixel p always draws from the same stream).
        if (options.time_budget_seconds == 0.0) {
          constexpr int kPasses = 32;
          options.spp_per_pass = std::max(1, (options.spp.value_or(scene.integrator.spp) + kPasses - 1) / kPasses);
          options.on_pass = [](int /*spp_done*/, double /*seconds*/, const rd::Image& /*image*/) {};
        }
        auto result = run_released(progress, [&](ProgressSink& p) { return rd::render(scene, options, p); });
        py::array_t<float> image = image_array(result.image, result.image.rgb);
        if (!stats) return image;
        py::dict s;
        s["variance"] = image_array(result.image, result.image.variance);
        s["integrator"] = result.stats.integrator;
        s["features"] = result.stats.features.names();
        s["spp"] = result.stats.spp;
        s["seconds"] = result.stats.seconds;
        s["paths"] = result.stats.paths;
        s["rays"] = result.stats.rays;
        s["invalid_samples"] = result.stats.invalid_samples;
        return py::make_tuple(image, s);
      },
      py::arg("kind"), py::arg("text"), py::arg("base_dir"), py::arg("spp"), py::arg("seed"), py::arg("integrator"),
      py::arg("time_budget"), py::arg("stats"), py::arg("progress"));
  m.def("builtin_scene_names", &rd::builtin_scene_names, "Names of the scenes compiled into weft (scenes/).");
  m.def(
      "builtin_scene", [](const std::string& name) { return std::string(rd::builtin_scene(name)); }, py::arg("name"),
      "The JSON text of a built-in scene.");
  m.def(
      "read_exr",
      [](const std::string& path) {
        const rd::Image image = rd::read_exr(path);
        return image_array(image, image.rgb);
      },
      py::arg("path"), "An RGB OpenEXR file as a float32 array H x W x 3 (what `weft render` writes).");
}

}  // namespace weft::python
