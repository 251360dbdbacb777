// The volumetric path tracer (weft/render): a scene file, built-in name or JSON text -> image.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "common.h"
#include "render_io.h"
#include "weft/render/builtin_scenes.h"
#include "weft/render/cloth_scene.h"
#include "weft/render/image.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/render/scene_checks.h"
#include "weft/render/world.h"

namespace weft::python {
namespace {

namespace rd = weft::render;
namespace vol = weft::volume;
namespace fs = std::filesystem;

rd::IntegratorChoice integrator_choice(const std::string& name) {
  if (name == "auto") return rd::IntegratorChoice::automatic;
  if (name == "surfaces") return rd::IntegratorChoice::surfaces;
  if (name == "exponential") return rd::IntegratorChoice::exponential;
  if (name == "general") return rd::IntegratorChoice::general;
  fail("render: integrator must be auto, surfaces, exponential or general, got '{}'", name);
}

using ImageArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// An (H, W, 3) array as the library's image; NaN and infinities are refused (a display file
// cannot hold them, and an EXR of them is rarely what was meant).
rd::Image image_of_array(const ImageArray& a, const char* what) {
  if (a.ndim() != 3 || a.shape(2) != 3)
    fail("{}: expected an image array of shape (H, W, 3), got {} dimensions{}", what, a.ndim(),
         a.ndim() == 3 ? fmt::format(" of shape ({}, {}, {})", a.shape(0), a.shape(1), a.shape(2)) : "");
  if (a.shape(0) < 1 || a.shape(1) < 1) fail("{}: the image is empty", what);
  rd::Image image;
  image.height = static_cast<int>(a.shape(0));
  image.width = static_cast<int>(a.shape(1));
  image.rgb.assign(a.data(), a.data() + a.size());
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    if (!std::isfinite(image.rgb[i]))
      fail("{}: pixel ({}, {}) is {}", what, i / 3 / image.width, i / 3 % image.width, image.rgb[i]);
  }
  return image;
}

}  // namespace

rd::SceneDesc scene_of(const std::string& kind, const std::string& text, const std::string& base_dir) {
  if (kind == "file") return rd::load_scene(text);
  if (kind == "builtin")
    return rd::parse_scene(rd::builtin_scene(text), "built-in scene '" + text + "'", fs::current_path());
  return rd::parse_scene(text, "scene dict", base_dir.empty() ? fs::current_path() : fs::path(base_dir));
}

py::array_t<float> image_array(const rd::Image& image, const std::vector<float>& values) {
  py::array_t<float> a({static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width), py::ssize_t{3}});
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

void init_render(py::module_& m) {
  m.def(
      "_render",
      [](const std::string& kind, const std::string& text, const std::string& base_dir, std::optional<int> spp,
         std::optional<std::uint64_t> seed, const std::string& integrator, double time_budget, bool stats,
         const py::object& progress) -> py::object {
        const rd::SceneDesc scene = scene_of(kind, text, base_dir);
        // The CLI's scene warnings (render/scene_checks.h), as weft.Warning (an error under
        // warnings.simplefilter("error")): the description's before the world is built, the
        // world's after.
        warn_all(rd::scene_warnings(scene), "weft.render");
        rd::RenderOptions options;
        if (spp) {
          if (*spp < 1) fail("render: spp must be >= 1, got {}", *spp);
          options.spp = *spp;
        }
        options.seed = seed;
        options.integrator = integrator_choice(integrator);
        options.time_budget_seconds = require_non_negative("render: time_budget", time_budget);
        // Progress and Ctrl-C come per unit of the render, which render() keeps short at any spp
        // (render/tiling.h, Tiling::kMaxUnitSamples).
        const rd::World world = run_released(progress, [&](ProgressSink&) { return rd::build_world(scene); });
        warn_all(rd::world_warnings(world), "weft.render");
        auto result = run_released(progress, [&](ProgressSink& p) { return rd::render(world, options, p); });
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
  m.def(
      "write_exr",
      [](const py::object& path, const ImageArray& image) {
        const rd::Image im = image_of_array(image, "write_exr");
        const std::string p = output_path_arg(path, "write_exr: path", false);
        py::gil_scoped_release release;
        rd::write_exr(p, im);
      },
      py::arg("path"), py::arg("image"),
      "Writes a linear RGB array (H, W, 3) as an OpenEXR file of 32-bit floats (what `weft render` writes), "
      "atomically.");
  m.def(
      "write_png",
      [](const py::object& path, const ImageArray& image, double exposure) {
        const rd::Image im = image_of_array(image, "write_png");
        require_positive("write_png: exposure", exposure);
        const std::string p = output_path_arg(path, "write_png: path", false);
        py::gil_scoped_release release;
        rd::write_png(p, im, exposure);
      },
      py::arg("path"), py::arg("image"), py::arg("exposure") = 1.0,
      "Writes a linear RGB array (H, W, 3) as an 8-bit sRGB PNG, scaled by exposure and clamped (the display "
      "image `weft render` writes), atomically.");
  m.def(
      "_cloth_scene_json",
      [](const vol::Grid& grid, const std::string& file_in_scene, const std::string& lighting, double tilt, int width,
         int height) {
        rd::ClothView view;
        view.lighting = rd::cloth_lighting(lighting);
        rd::check_cloth_tilt("cloth_scene", tilt);
        if (width < 1 || height < 1) fail("cloth_scene: width and height must be >= 1, got {}x{}", width, height);
        view.tilt_degrees = tilt;
        view.width = width;
        view.height = height;
        return rd::cloth_scene_json(grid, file_in_scene, {}, view);
      },
      py::arg("grid"), py::arg("file_in_scene"), py::arg("lighting"), py::arg("tilt"), py::arg("width"),
      py::arg("height"));
  m.def("builtin_scene_names", &rd::builtin_scene_names, "Names of the scenes compiled into weft (scenes/).");
  m.def(
      "builtin_scene", [](const std::string& name) { return std::string(rd::builtin_scene(name)); }, py::arg("name"),
      "The JSON text of a built-in scene.");
  m.def(
      "read_exr",
      [](const py::object& path) {
        const rd::Image image = rd::read_exr(path_arg(path, "read_exr: path"));
        return image_array(image, image.rgb);
      },
      py::arg("path"), "An RGB OpenEXR file as a float32 array H x W x 3 (what `weft render` writes).");
}

}  // namespace weft::python
