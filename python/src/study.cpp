// The coarse-cloth image study and its matrix (weft/study; docs/render.md §6c-§6e) and the
// baselines' downsampling: thin calls of the library with the CLI's defaults, whose reports are
// the library's own JSON and CSV writers (so a column the library adds reaches Python unedited).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "common.h"
#include "render_io.h"
#include "weft/core/front_end.h"
#include "weft/dist/unit_store.h"
#include "weft/fit/scale.h"
#include "weft/render/cloth_scene.h"
#include "weft/study/albedo_fit.h"
#include "weft/study/render_matrix.h"
#include "weft/study/render_matrix_report.h"
#include "weft/study/render_study.h"
#include "weft/study/render_study_report.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/downsample.h"
#include "weft/volume/provenance.h"
#include "weft/volume/shadowed_downsample.h"

namespace weft::python {
namespace {

namespace fs = std::filesystem;
namespace st = weft::study;

// The library's defaults are the CLI's (study::default_study_spec, default_matrix_spec, and
// --quick's film, render::shrink_film with render::kQuickFilmSide).

template <typename T>
std::optional<T> get(const py::dict& o, const char* key) {
  if (!o.contains(key) || o[key].is_none()) return std::nullopt;
  return arg_cast<T>(o[key], key, "of its documented type (an integer within its C++ range, a number, ...)");
}

std::string shown(const std::vector<int>& v) { return fmt::format("[{}]", fmt::join(v, ", ")); }
std::string shown(const std::vector<double>& v) { return fmt::format("[{}]", fmt::join(v, ", ")); }
std::string shown(const std::vector<std::string>& v) {
  std::vector<std::string> quoted;
  quoted.reserve(v.size());
  for (const auto& s : v) quoted.push_back("'" + s + "'");
  return fmt::format("[{}]", fmt::join(quoted, ", "));
}

/// Runs `apply` (one argument into the spec, then the library's check of the whole spec) and
/// raises a weft::Error again naming the argument as the caller wrote it: the arguments are
/// applied one by one to a valid spec, so the first failing check is that argument's.
template <typename Fn>
void argument(const char* call, const std::string& name_value, Fn&& apply) {
  try {
    apply();
  } catch (const Error& e) {
    fail("{}: {}: {}", call, name_value, e.what());
  }
}

/// The study's spec from the Python arguments (None: the CLI's default), checked.
st::StudySpec study_spec(const py::dict& o, const char* call, bool matrix) {
  const bool quick = get<bool>(o, "quick").value_or(false);
  st::StudySpec spec = matrix ? st::default_matrix_spec(quick).study : st::default_study_spec(quick);
  spec.work_dir = "(the out folder)";  // set by the caller; checked here for the other fields
  spec.front = FrontEnd::python;
  const auto check = [&] { st::check_study_spec(spec, FrontEnd::python); };
  // albedo="fit": albedo-corrected candidates will be rendered (components= may name them).
  if (!matrix) spec.albedo_fitted = get<bool>(o, "fit_albedo").value_or(false);
  if (auto f = get<std::vector<int>>(o, "factors")) {
    argument(call, "factors=" + shown(*f), [&] {
      std::vector<int> sorted = *f;  // the CLI runs them in increasing order
      std::sort(sorted.begin(), sorted.end());
      spec.factors = sorted;
      spec.factors_given = true;
      check();
    });
  }
  if (auto names = get<std::vector<std::string>>(o, "memory")) {
    argument(call, "memory=" + shown(*names), [&] {
      spec.memory_rules.clear();
      for (const std::string& name : *names) {
        const auto rule = transmittance::parse_memory_rule(name);
        if (!rule) fail("unknown memory rule '{}' (segment, renewal, optical-depth, carried)", name);
        spec.memory_rules.push_back(*rule);
      }
      if (spec.memory_rules.empty()) fail("no memory rule");
      check();
    });
  }
  if (auto spp = get<int>(o, "spp")) {
    argument(call, fmt::format("spp={}", *spp), [&] {
      if (*spp < 1) fail("must be >= 1 (None: {})", matrix ? "the default" : "a time budget of seconds=");
      spec.spp = *spp;
      check();
    });
  }
  if (auto seconds = get<double>(o, "seconds")) {
    argument(call, fmt::format("seconds={}", *seconds), [&] {
      spec.seconds = *seconds;
      check();
    });
  }
  if (auto ref = get<int>(o, "reference_spp")) {
    argument(call, fmt::format("reference_spp={}", *ref), [&] {
      spec.reference_spp = *ref;
      check();
    });
  }
  if (auto window = get<std::string>(o, "window")) {
    argument(call, fmt::format("window='{}'", *window), [&] {
      fit::check_scale_text(*window);
      spec.scale = *window;
    });
  }
  if (auto pairs = get<std::vector<std::pair<int, double>>>(o, "albedo")) {
    std::vector<std::string> items;
    for (const auto& [f, k] : *pairs) items.push_back(fmt::format("{}: {}", f, k));
    argument(call, fmt::format("albedo={{{}}}", fmt::join(items, ", ")), [&] {
      spec.albedo_factors = *pairs;
      check();
    });
  }
  if (auto names = get<std::vector<std::string>>(o, "components")) {
    argument(call, "components=" + shown(*names), [&] {
      spec.components = *names;
      check();
    });
  }
  if (auto seed = get<std::uint64_t>(o, "seed")) spec.seed = *seed;
  return spec;
}

/// The scene of a single study: the caller's, with --quick's small film (same view).
render::SceneDesc study_scene(const py::dict& o, const char* call) {
  render::SceneDesc scene =
      scene_of(o["kind"].cast<std::string>(), o["text"].cast<std::string>(), o["base_dir"].cast<std::string>());
  argument(call, "scene", [&] { st::check_study_scene(scene); });
  if (get<bool>(o, "quick").value_or(false)) render::shrink_film(scene.camera, render::kQuickFilmSide);
  return scene;
}

py::dict albedo_fit_dict(const st::AlbedoFit& f) {
  py::dict d;
  d["factor"] = f.factor;
  d["k"] = f.k;
  d["target"] = f.target;
  d["fitted"] = f.fitted;
  d["tolerance"] = f.tolerance;
  d["renders"] = f.renders;
  d["converged"] = f.converged;
  // Fitted to images of the fine grid (albedo_fit.h): labelled as the study labels its candidates.
  d["fitted_to_images"] = true;
  d["uses_ground_truth"] = true;
  return d;
}

py::array_t<bool> mask_array(const render::Image& image, const std::vector<bool>& mask) {
  py::array_t<bool> a({static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width)});
  bool* out = a.mutable_data();
  for (std::size_t i = 0; i < static_cast<std::size_t>(a.size()); ++i) out[i] = i < mask.size() && mask[i];
  return a;
}

}  // namespace

void init_study(py::module_& m) {
  m.def(
      "_render_study",
      [](const py::dict& o, const std::string& work_dir, const py::object& progress) {
        constexpr const char* call = "render_study";
        st::StudySpec spec = study_spec(o, call, false);
        if (get<int>(o, "spp") && get<double>(o, "seconds"))
          fail("render_study: spp= and seconds= exclude each other (a fixed spp, or a time budget per image)");
        const render::SceneDesc scene = study_scene(o, call);
        // The scene against the whole spec (albedo factors past the scene's albedo, the work the
        // film and spp make) before anything runs, under the call's name as every other check.
        try {
          st::check_study_scene(scene, spec);
        } catch (const Error& e) {
          fail("{}: {}", call, e.what());
        }
        const bool fit = get<bool>(o, "fit_albedo").value_or(false);
        spec.work_dir = work_dir;
        std::vector<st::AlbedoFit> fits;
        const st::StudyResult r = run_released(progress, [&](ProgressSink& p) {
          if (fit) {
            // As `weft render --study --study-albedo fit`: fitted on this scene (in-sample here).
            fits = st::fit_albedo(scene, spec, p);
            spec.albedo_factors.clear();
            for (const st::AlbedoFit& f : fits) spec.albedo_factors.emplace_back(f.factor, f.k);
          }
          return st::run_study(scene, spec, p);
        });
        py::dict out;
        out["json"] = st::study_json(r);
        out["csv"] = st::study_csv(r);
        out["curves_csv"] = st::study_curves_csv(r);
        out["reference"] = image_array(r.reference, r.reference.rgb);
        out["reference_variance"] = image_array(r.reference, r.reference.variance);
        out["cloth_mask"] = mask_array(r.reference, r.cloth_mask);
        py::list images;
        py::list error_maps;
        for (const st::StudyCandidate& c : r.candidates) {
          images.append(image_array(c.image, c.image.rgb));
          error_maps.append(image_array(c.error_map, c.error_map.rgb));
        }
        out["images"] = images;
        out["error_maps"] = error_maps;
        py::list fitted;
        for (const st::AlbedoFit& f : fits) fitted.append(albedo_fit_dict(f));
        out["albedo_fits"] = fitted;
        return out;
      },
      py::arg("options"), py::arg("work_dir"), py::arg("progress"),
      "The image study (study::run_study) and its reports; use weft.render_study.");

  m.def(
      "_fit_albedo",
      [](const py::dict& o, const std::string& work_dir, const py::object& progress) {
        constexpr const char* call = "fit_albedo";
        st::StudySpec spec = study_spec(o, call, false);
        const render::SceneDesc scene = study_scene(o, call);
        spec.work_dir = work_dir;
        const auto fits = run_released(progress, [&](ProgressSink& p) { return st::fit_albedo(scene, spec, p); });
        py::list out;
        for (const st::AlbedoFit& f : fits) out.append(albedo_fit_dict(f));
        return out;
      },
      py::arg("options"), py::arg("work_dir"), py::arg("progress"),
      "The albedo factors k_N (study::fit_albedo); use weft.fit_albedo.");

  m.def(
      "_render_matrix",
      [](const py::dict& o, const std::string& work_dir, bool keep_units, bool resume, const py::object& progress) {
        constexpr const char* call = "render_matrix";
        st::MatrixSpec spec = st::default_matrix_spec(get<bool>(o, "quick").value_or(false));
        spec.study = study_spec(o, call, true);
        const auto check = [&] { st::check_matrix_spec(spec, FrontEnd::python); };
        if (auto cloths = get<std::vector<std::string>>(o, "cloths"))
          argument(call, "cloths=" + shown(*cloths), [&] {
            spec.cloths = *cloths;
            check();
          });
        if (auto names = get<std::vector<std::string>>(o, "lightings"))
          argument(call, "lightings=" + shown(*names), [&] {
            spec.lightings.clear();
            for (const std::string& name : *names) spec.lightings.push_back(render::cloth_lighting(name));
            check();
          });
        if (auto tilts = get<std::vector<double>>(o, "tilts"))
          argument(call, "tilts=" + shown(*tilts), [&] {
            spec.tilts = *tilts;
            check();
          });
        if (auto film = get<std::pair<int, int>>(o, "film"))
          argument(call, fmt::format("film=({}, {})", film->first, film->second), [&] {
            spec.width = film->first;
            spec.height = film->second;
            check();
          });
        if (auto yarns = get<int>(o, "yarns"))
          argument(call, fmt::format("yarns={}", *yarns), [&] {
            spec.yarns = *yarns;
            check();
          });
        spec.study.work_dir = work_dir;
        spec.study.seed = get<std::uint64_t>(o, "seed").value_or(1);
        check();
        // As the CLI: finished cases kept in <out>/matrix.units, keyed by the spec (--resume).
        std::optional<dist::UnitStore> store;
        if (keep_units)
          store.emplace(fs::path(work_dir) / "matrix.units", st::matrix_key(spec), resume, FrontEnd::python);
        const auto results =
            run_released(progress, [&](ProgressSink& p) { return st::run_matrix(spec, p, store ? &*store : nullptr); });
        const auto headlines = st::matrix_headlines(spec, results);
        py::dict out;
        out["json"] = st::matrix_json(spec, results, headlines);
        out["csv"] = st::matrix_csv(results);
        out["cost_csv"] = st::matrix_cost_csv(results);
        out["markdown"] = st::matrix_markdown(headlines, results);
        out["resumed"] = store ? store->found() : 0;
        return out;
      },
      py::arg("options"), py::arg("work_dir"), py::arg("keep_units"), py::arg("resume"), py::arg("progress"),
      "The study matrix (study::run_matrix) and its reports; use weft.render_matrix.");

  py::class_<volume::ShadowedGrids>(m, "ShadowedGrids",
                                    "The grids of weft.shadowed_downsample: per axis and isotropic (docs/render.md "
                                    "§6d (c)).")
      .def_property_readonly(
          "per_axis",
          [](const volume::ShadowedGrids& g) { return py::make_tuple(g.per_axis[0], g.per_axis[1], g.per_axis[2]); },
          "(x, y, z): per axis a, the value whose extinction through a block along a transmits the block's mean "
          "transmittance along a.")
      .def_readonly("isotropic", &volume::ShadowedGrids::isotropic,
                    "The mean of the three (the isotropic part of the direction-dependent extinction): what the "
                    "study's shadow-corrected candidates render.")
      .def("__repr__", [](const volume::ShadowedGrids& g) {
        return fmt::format("<weft.ShadowedGrids voxel_size={:g} active_voxels={}>", g.isotropic.voxel_size(),
                           g.isotropic.active_voxel_count());
      });
  m.def(
      "_shadowed_downsample",
      [](const volume::Grid& grid, int factor, std::optional<double> sigma) {
        const double scale = grid_sigma(grid, sigma, "shadowed_downsample").sigma;
        py::gil_scoped_release release;
        try {
          return volume::shadowed_downsample(grid, factor, scale);
        } catch (const Error& e) {
          fail("shadowed_downsample: {}", e.what());
        }
      },
      py::arg("grid"), py::arg("factor"), py::arg("sigma"));
  m.def(
      "_downsample",
      [](const volume::Grid& grid, int factor) {
        py::gil_scoped_release release;
        return volume::downsample(grid, factor);  // its errors already start "downsample: "
      },
      py::arg("grid"), py::arg("factor"));
}

}  // namespace weft::python
