// The main job's stages: ground truth by DDA (weft/volume/beam.h), window statistics and the
// gamma model they predict, least-squares fits and curve errors (weft/fit/gamma_moments.h, least_squares.h).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "common.h"
#include "weft/fit/gamma_moments.h"
#include "weft/fit/least_squares.h"
#include "weft/fit/local_fields.h"
#include "weft/fit/report.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/fit/window_stats.h"
#include "weft/render/local_gamma_beam.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/beam.h"
#include "weft/volume/beam_checks.h"
#include "weft/volume/provenance.h"

namespace weft::python {
namespace {

namespace vol = weft::volume;
namespace fit = weft::fit;

// A beam's direction from axis= or direction=; each refusal names the called function `call`
// once ("measure_fields_beam: direction ...", never another call's name).
std::array<double, 3> direction_of(const char* call, const py::object& axis, const py::object& direction) {
  if (!axis.is_none() && !direction.is_none()) fail("{}: give axis or direction, not both", call);
  if (!direction.is_none()) {
    if (py::isinstance<py::str>(direction)) return vol::parse_direction(direction.cast<std::string>());
    std::array<double, 3> d{};
    try {
      d = direction.cast<std::array<double, 3>>();
    } catch (const py::cast_error&) {
      throw py::type_error(fmt::format("{}: direction must be 3 numbers or 'dx,dy,dz'", call));
    }
    const std::string what = fmt::format("{}: direction", call);
    for (double c : d) require_finite(what.c_str(), c);
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0) fail("{}: direction must not be zero", call);
    return d;
  }
  if (axis.is_none()) return {0.0, 0.0, 1.0};
  if (py::isinstance<py::str>(axis)) {
    // A signed axis ('-y'): the parsed direction, whose other components are +0.
    const auto text = axis.cast<std::string>();
    std::array<double, 3> d{0.0, 0.0, 0.0};
    try {
      d = vol::parse_direction(text);
    } catch (const Error&) {
      d = {1.0, 1.0, 1.0};  // not an axis: refused below
    }
    if (vol::beam_axis(d) < 0)
      fail("{}: axis must be 0, 1, 2 or 'x', 'y', 'z' (optionally signed), got '{}'", call, text);
    return d;
  }
  std::array<double, 3> d{0.0, 0.0, 0.0};
  d[static_cast<std::size_t>(axis_index(axis, fmt::format("{}: axis", call).c_str()))] = 1.0;
  return d;
}

py::array_t<double> transmittance(const vol::TransmittanceCurve& c) {
  std::vector<double> t(c.size());
  for (std::size_t k = 0; k < c.size(); ++k) t[k] = c.transmittance(k);
  return move_to_array(std::move(t));
}

py::array_t<double> stderr_abs(const vol::TransmittanceCurve& c) {
  std::vector<double> s(c.size());
  for (std::size_t k = 0; k < c.size(); ++k) s[k] = c.stderr_abs(k);
  return move_to_array(std::move(s));
}

}  // namespace

void init_measure(py::module_& m) {
  py::class_<vol::TransmittanceCurve>(m, "TransmittanceCurve",
                                      "Ground-truth T(t) of a beam: depths from the entry face, T, log T and the\n"
                                      "standard error of T (the mean over rays of exp(-tau)).")
      .def_property_readonly(
          "depth", [](const vol::TransmittanceCurve& c) { return to_array(c.depth); },
          "World distance from the entry face [length].")
      .def_property_readonly("T", &transmittance, "Mean over rays of exp(-tau(t)).")
      .def_property_readonly("log_T", [](const vol::TransmittanceCurve& c) { return to_array(c.log_t); })
      .def_property_readonly("stderr", &stderr_abs, "Standard error of T over the rays.")
      .def_property_readonly("rel_stderr", [](const vol::TransmittanceCurve& c) { return to_array(c.rel_stderr); })
      .def_readonly("rays", &vol::TransmittanceCurve::distinct_rays,
                    "Rays that entered the box, an axis column's rays counted once (the samples behind the\n"
                    "standard error, taken as independent; measure.json's \"rays\").")
      .def_readonly("rays_traced", &vol::TransmittanceCurve::rays, "Rays traced that entered the box.")
      .def_readonly("direction", &vol::TransmittanceCurve::direction, "Unit direction of travel.")
      .def_readonly("method", &vol::TransmittanceCurve::method)
      .def("__len__", &vol::TransmittanceCurve::size)
      .def("__repr__",
           [](const vol::TransmittanceCurve& c) {
             return fmt::format(
                 "<weft.TransmittanceCurve {} depths to {:.4g}, T_end {:.4g}, {} rays, direction ({:.3g}, "
                 "{:.3g}, {:.3g})>",
                 c.size(), c.depth.empty() ? 0.0 : c.depth.back(), c.log_t.empty() ? 1.0 : std::exp(c.log_t.back()),
                 c.distinct_rays, c.direction[0], c.direction[1], c.direction[2]);
           })
      .def("__iter__", [](const vol::TransmittanceCurve& c) {
        // depths, T, stderr = weft.measure_beam(...)
        return py::iter(py::make_tuple(to_array(c.depth), transmittance(c), stderr_abs(c)));
      });

  m.def(
      "measure_beam",
      named_call("measure_beam",
                 [](const vol::Grid& grid, const py::object& axis, const py::object& direction,
                    const std::optional<double>& sigma, int rays_per_column, bool jitter, std::uint64_t seed,
                    double depth_step, const std::string& method, int column_stride, bool full_chords,
                    const py::object& progress) {
                   vol::BeamSpec spec;
                   spec.direction = direction_of("measure_beam", axis, direction);
                   spec.full_chords = full_chords;
                   // The CLI's rule (weft measure), in Python's words.
                   vol::check_rays_per_column({spec.direction}, rays_per_column, jitter, FrontEnd::python);
                   vol::check_full_chords({spec.direction}, full_chords, FrontEnd::python);
                   // σ as `weft measure` picks it: sigma=, else the grid's provenance, never a silent 1.
                   spec.scale = grid_sigma(grid, sigma, "measure_beam").sigma;
                   if (column_stride < 1 || column_stride > 4096)
                     fail("measure_beam: column_stride must be in 1..4096, got {}", column_stride);
                   spec.rays_per_column = rays_per_column;
                   spec.jitter = jitter;  // rays_per_column > 1 jitters anyway (beam.h)
                   spec.seed = seed;
                   spec.depth_step = require_non_negative("measure_beam: depth_step", depth_step);
                   spec.method = vol::parse_beam_method(method);
                   vol::check_beam_method(spec.method, {spec.direction}, FrontEnd::python);
                   spec.column_stride = column_stride;
                   vol::check_full_chord_rays(vol::active_world_box(grid), grid.voxel_size(), spec, FrontEnd::python);
                   return run_released(progress, [&](ProgressSink& p) { return vol::measure_beam(grid, spec, p); });
                 }),
      py::arg("grid"), py::arg("axis") = py::none(), py::kw_only(), py::arg("direction") = py::none(),
      py::arg("sigma") = py::none(), py::arg("rays_per_column") = 1, py::arg("jitter") = false, py::arg("seed") = 1,
      py::arg("depth_step") = 0.0, py::arg("method") = "auto", py::arg("column_stride") = 1,
      py::arg("full_chords") = false, py::arg("progress") = py::none(),
      "measure_beam(grid, axis='z' | direction=(dx, dy, dz), sigma=None, ...) -> TransmittanceCurve\n\n"
      "Ground-truth transmittance of a beam of parallel rays through the grid's active box by DDA\n"
      "(mu = sigma * value; sigma None: the grid's provenance, 1 for extinction values, else an error). axis: 0/1/2 or "
      "'x', '-y', ...; direction: any non-zero vector (or 'dx,dy,dz').\n"
      "method: 'auto', 'streaming', 'per-ray', 'openvdb'. full_chords: oblique beams keep only the rays crossing the\n"
      "box face to face (--full-chords). progress: callable(label, done, total).\n"
      "Unpacks as depths, T, stderr. Same numbers as `weft measure` for the same options.");

  m.def(
      "measure_fields_beam",
      named_call(
          "measure_fields_beam",
          [](const py::object& fields, const vol::Grid& grid, const py::object& axis, const py::object& direction,
             const std::optional<double>& sigma, const std::string& memory, int rays_per_column, bool jitter,
             std::uint64_t seed, double depth_step, int column_stride, bool full_chords, const py::object& progress) {
            vol::BeamSpec spec;
            spec.direction = direction_of("measure_fields_beam", axis, direction);
            spec.full_chords = full_chords;
            vol::check_rays_per_column({spec.direction}, rays_per_column, jitter, FrontEnd::python);
            vol::check_full_chords({spec.direction}, full_chords, FrontEnd::python);
            if (column_stride < 1 || column_stride > 4096)
              fail("measure_fields_beam: column_stride must be in 1..4096, got {}", column_stride);
            spec.rays_per_column = rays_per_column;
            spec.jitter = jitter;
            spec.seed = seed;
            spec.depth_step = require_non_negative("measure_fields_beam: depth_step", depth_step);
            spec.column_stride = column_stride;
            vol::check_full_chord_rays(vol::active_world_box(grid), grid.voxel_size(), spec, FrontEnd::python);
            const auto rule = transmittance::parse_memory_rule(memory);
            if (!rule)
              fail("measure_fields_beam: unknown memory rule '{}' (optical-depth, segment, renewal, carried)", memory);
            // σ and the value kind as `weft measure --fields` takes them: the grid's.
            const render::FieldsSpec f{path_arg(fields, "measure_fields_beam: fields"),
                                       grid_sigma(grid, sigma, "measure_fields_beam").sigma,
                                       vol::read_provenance(grid).value_kind == "extinction", *rule, FrontEnd::python};
            return run_released(progress,
                                [&](ProgressSink& p) { return render::predict_fields_beam(f, grid, spec, p); });
          }),
      py::arg("fields"), py::arg("grid"), py::arg("axis") = py::none(), py::kw_only(),
      py::arg("direction") = py::none(), py::arg("sigma") = py::none(), py::arg("memory") = "optical-depth",
      py::arg("rays_per_column") = 1, py::arg("jitter") = false, py::arg("seed") = 1, py::arg("depth_step") = 0.0,
      py::arg("column_stride") = 1, py::arg("full_chords") = false, py::arg("progress") = py::none(),
      "measure_fields_beam(fields, grid, axis='z' | direction=(dx, dy, dz), sigma=None, memory='optical-depth', ...)\n"
      "-> TransmittanceCurve\n\n"
      "The beam measure_beam(grid, ...) traces, predicted from local-gamma fields of the grid (the path of\n"
      "weft fit --block's local_fields.vdb, or of local_fields(grid, B).save(path)): every ray walked through\n"
      "the coarse cells under the memory rule, as the render's local-gamma medium walks it; the same rays, depths\n"
      "and sigma as measure_beam. Same numbers as `weft measure --fields`.");

  py::class_<fit::ConcentrationStats>(m, "ConcentrationStats", "Mean and variance of window-mean concentration.")
      .def(py::init<>())
      .def_readwrite("mean", &fit::ConcentrationStats::mean)
      .def_readwrite("variance", &fit::ConcentrationStats::variance, "Population variance over the samples.")
      .def_readwrite("samples", &fit::ConcentrationStats::samples)
      .def_readwrite("window_voxels", &fit::ConcentrationStats::window_voxels)
      .def_readwrite("window", &fit::ConcentrationStats::window, "Window length used [length].")
      .def("__repr__", [](const fit::ConcentrationStats& s) {
        return fmt::format("<weft.ConcentrationStats mean={} variance={} samples={} window={}>", s.mean, s.variance,
                           s.samples, s.window);
      });

  py::class_<fit::GammaFit>(m, "GammaFit", "A gamma concentration law (Eq. 19): alpha = C^2/Var C, beta = C/Var C.")
      .def(py::init<>())
      .def_readwrite("sigma", &fit::GammaFit::sigma)
      .def_readwrite("mean_concentration", &fit::GammaFit::mean_concentration)
      .def_readwrite("var_concentration", &fit::GammaFit::var_concentration)
      .def_readwrite("alpha", &fit::GammaFit::alpha, "+inf in the exponential limit.")
      .def_readwrite("beta", &fit::GammaFit::beta)
      .def_property_readonly("exponential", &fit::GammaFit::exponential)
      .def_property_readonly("mean_extinction", &fit::GammaFit::mean_extinction, "sigma * mean concentration.")
      .def(
          "law", [](const fit::GammaFit& f) { return py_law(fit::model_law(f)); },
          "The model's law: gamma, or exponential when Var C = 0.")
      .def(
          "exponential_law", [](const fit::GammaFit& f) { return py_law(fit::exponential_law(f)); },
          "The exponential baseline with the same mean extinction.")
      .def("__repr__", [](const fit::GammaFit& f) {
        return fmt::format("<weft.GammaFit sigma={} mean={} var={} alpha={} beta={}>", f.sigma, f.mean_concentration,
                           f.var_concentration, f.alpha, f.beta);
      });

  py::class_<fit::LeastSquaresFit>(m, "LeastSquaresFit", "Levenberg-Marquardt fit of (alpha, beta) at fixed sigma.")
      .def_readonly("fit", &fit::LeastSquaresFit::fit)
      .def_readonly("rms", &fit::LeastSquaresFit::rms, "RMS residual on T.")
      .def_readonly("iterations", &fit::LeastSquaresFit::iterations)
      .def_readonly("converged", &fit::LeastSquaresFit::converged)
      .def("__repr__", [](const fit::LeastSquaresFit& f) {
        return fmt::format("<weft.LeastSquaresFit alpha={:.4g} beta={:.4g} rms={:.3g} iterations={}{}>", f.fit.alpha,
                           f.fit.beta, f.rms, f.iterations, f.converged ? "" : " (not converged)");
      });

  // Local statistic fields (fit/local_fields.h): what `weft fit --block B` writes as
  // local_fields.vdb, rendered by a "local-gamma" scene medium (docs/scene-format.md).
  py::class_<fit::LocalFields>(m, "LocalFields",
                               "Per block of B^3 voxels: the mean concentration and, per axis, the variance of the\n"
                               "column means and the gamma (alpha, beta) they give (weft fit --block B).")
      .def_readonly("block", &fit::LocalFields::block, "Block edge B in voxels.")
      .def_readonly("blocks", &fit::LocalFields::blocks, "Blocks with data.")
      .def_readonly("mean", &fit::LocalFields::mean, "Grid 'mean_concentration'.")
      .def_property_readonly(
          "variance",
          [](const fit::LocalFields& f) { return py::make_tuple(f.variance[0], f.variance[1], f.variance[2]); },
          "Grids 'var_concentration_x', '_y', '_z', stored as half floats (values already rounded) when all fit its\n"
          "range (always for concentrations in [0, 1]), as floats otherwise.")
      .def_property_readonly(
          "alpha", [](const fit::LocalFields& f) { return py::make_tuple(f.alpha[0], f.alpha[1], f.alpha[2]); })
      .def_property_readonly("beta",
                             [](const fit::LocalFields& f) { return py::make_tuple(f.beta[0], f.beta[1], f.beta[2]); })
      .def(
          "save",
          [](const fit::LocalFields& f, const py::object& path) {
            const std::string p = output_path_arg(path, "LocalFields.save: path", false);
            py::gil_scoped_release release;
            fit::save_local_fields(f, p, fit::FieldChannels::all);
          },
          py::arg("path"), "Writes every grid into one .vdb file (local_fields.vdb of weft fit --block), atomically.")
      .def("__repr__", [](const fit::LocalFields& f) {
        return fmt::format("<weft.LocalFields block={} blocks={} voxel_size={}>", f.block, f.blocks,
                           f.mean.voxel_size());
      });
  m.def(
      "local_fields",
      [](const vol::Grid& grid, int block, const py::object& progress) {
        // `weft fit --block`'s refusal of a block the cloth does not fill (docs/validate.md "Local fields").
        if (const auto whole = fit::whole_box_block(block, grid))
          fail(
              "local_fields: block={}: {}: the fields would be one homogeneous block, the cloth's concentration "
              "spread over the vacuum around it; use a block below {}",
              block, whole->text, whole->below);
        // ... and its warning of a block thicker than the cloth, as a weft.Warning.
        if (std::string note = fit::thick_block_note(block, grid); !note.empty())
          warn_all({std::move(note)}, "weft.local_fields");
        return run_released(progress, [&](ProgressSink& p) { return fit::local_fields(grid, block, p); });
      },
      py::arg("grid"), py::arg("block"), py::kw_only(), py::arg("progress") = py::none(),
      "Local statistic fields per block of block^3 voxels, as `weft fit --block` computes them (its checks of\n"
      "the block size and memory estimate included: a block at or above the active box's largest extent is a\n"
      "weft.Error, one above its smallest a weft.Warning); a LocalFields.");

  py::class_<fit::CurveError>(m, "CurveError", "Errors of a model against the ground truth on its depth grid.")
      .def_readonly("max_abs_t", &fit::CurveError::max_abs_t)
      .def_readonly("rms_abs_t", &fit::CurveError::rms_abs_t)
      .def_readonly("max_abs_log_t", &fit::CurveError::max_abs_log_t, "Over depths where T_gt > 1e-6.")
      .def_readonly("rms_abs_log_t", &fit::CurveError::rms_abs_log_t)
      .def_readonly("mean_log_bias", &fit::CurveError::mean_log_bias, "< 0: the model overestimates extinction.")
      .def_readonly("below_fraction", &fit::CurveError::below_fraction)
      .def_readonly("log_points", &fit::CurveError::log_points)
      .def("__repr__", [](const fit::CurveError& e) {
        return fmt::format("<weft.CurveError max_abs_t={:.4g} rms_abs_t={:.4g} mean_log_bias={:.4g}>", e.max_abs_t,
                           e.rms_abs_t, e.mean_log_bias);
      });

  m.def(
      "window_stats",
      [](const vol::Grid& grid, const py::object& axis, double window, const py::object& progress) {
        const int a = axis_index(axis, "window_stats: axis");
        require_non_negative("window_stats: window", window);
        return run_released(progress, [&](ProgressSink& p) { return fit::window_stats(grid, a, window, p); });
      },
      py::arg("grid"), py::arg("axis"), py::arg("window") = 0.0, py::arg("progress") = py::none(),
      "Mean and variance of the concentration averaged over windows of `window` (0 = the grid's extent)\n"
      "along `axis`, every window position of every column a sample (weft/fit/window_stats.h).");
  m.def(
      "correlation_length",
      [](const vol::Grid& grid, const py::object& axis, const py::object& progress) {
        const int a = axis_index(axis, "correlation_length: axis");
        return run_released(progress, [&](ProgressSink& p) { return fit::correlation_length(grid, a, p); });
      },
      py::arg("grid"), py::arg("axis"), py::arg("progress") = py::none(),
      "Lag at which the autocorrelation of C along `axis` first falls to 1/e [length].");
  m.def("pool", &fit::pool, py::arg("per_axis"),
        "Isotropic statistics: several axes' samples pooled with equal weight.");
  m.def("gamma_from_moments", &fit::gamma_from_moments, py::arg("mean"), py::arg("variance"), py::arg("sigma"),
        "The gamma law by moment matching (Eq. 19).");
  m.def(
      "fit_gamma_to_curve",
      [](const vol::TransmittanceCurve& curve, double sigma, const std::optional<fit::GammaFit>& start) {
        require_positive("fit_gamma_to_curve: sigma", sigma);
        const fit::GammaFit s = start.value_or(fit::GammaFit{sigma, 0.0, 0.0, 0.0, 0.0});
        py::gil_scoped_release release;
        return fit::fit_gamma_to_curve(curve, sigma, s);
      },
      py::arg("curve"), py::arg("sigma"), py::arg("start") = py::none(),
      "Best least-squares gamma law to a ground-truth curve (what any gamma law can do at best).");
  m.def(
      "log_curve",
      [](const transmittance::Law& law, const std::vector<double>& depths) {
        for (std::size_t k = 0; k < depths.size(); ++k) {
          if (std::isnan(depths[k]) || depths[k] < 0.0)
            fail("log_curve: depths must be >= 0, got {} at index {}", depths[k], k);
        }
        return to_array(fit::log_curve(law, depths));
      },
      py::arg("law"), py::arg("depths"), "log T of `law` at `depths` (a numpy array).");
  m.def(
      "compare",
      [](const vol::TransmittanceCurve& curve, const std::vector<double>& model_log_t) {
        if (model_log_t.size() != curve.size())
          fail("compare: model_log_t has {} values, the curve {} depths", model_log_t.size(), curve.size());
        return fit::compare(curve, model_log_t);
      },
      py::arg("curve"), py::arg("model_log_t"), "Errors of a model's log T against the ground truth.");

  m.def(
      "_validate_json",
      [](const vol::Grid& grid, const py::object& sigma, const std::string& window, const std::string& axes,
         int rays_per_column, std::uint64_t seed, const std::string& models, const py::object& progress) {
        // The same rules as `weft validate --grid`: σ from sigma= or the provenance, the scale from
        // fit::resolve_scale, the report's science part from fit::validation_json; and the curves
        // behind it (the report's figure) as arrays.
        const vol::Provenance prov = vol::read_provenance(grid);
        fit::ValidationSpec spec;
        const vol::SigmaChoice chosen =
            grid_sigma(grid,
                       sigma.is_none() ? std::nullopt
                                       : std::optional<double>(arg_cast<double>(sigma, "validate: sigma", "a number")),
                       "validate");
        spec.sigma = chosen.sigma;
        const std::string& sigma_source = chosen.source;
        // The checks of `weft validate`, in Python's words.
        fit::check_scale_text(window);
        spec.directions = fit::parse_axes(axes);
        spec.models = fit::ModelSelection::parse(models);
        vol::check_rays_per_column(spec.directions, rays_per_column, false, FrontEnd::python);
        spec.rays_per_column = rays_per_column;
        spec.seed = seed;
        fit::StatisticsScale scale;
        const fit::Validation v = run_released(progress, [&](ProgressSink& p) {
          scale = fit::resolve_scale(window, grid, prov, p, FrontEnd::python);
          spec.scale = scale.length;
          return fit::validate(grid, spec, p);
        });
        const fit::ScaleUse used = fit::scale_use(scale, grid, spec.models.needs_blocks(), FrontEnd::python);
        warn_all(used.notes, "weft.validate");
        py::list curves;
        for (const fit::AxisValidation& a : v.axes) {
          py::dict c;
          c["depth"] = to_array(a.ground_truth.depth);
          c["T_gt"] = transmittance(a.ground_truth);
          c["stderr"] = stderr_abs(a.ground_truth);
          py::dict models;
          for (const fit::ModelCurve& m : a.models) {
            std::vector<double> t(m.log_t.size());
            std::transform(m.log_t.begin(), m.log_t.end(), t.begin(), [](double l) { return std::exp(l); });
            models[py::str(m.name)] = move_to_array(std::move(t));
          }
          c["T"] = models;
          curves.append(c);
        }
        py::dict window_info;
        window_info["rule"] = scale.rule;
        window_info["source"] = scale.source;
        window_info["length"] = py::make_tuple(scale.length[0], scale.length[1], scale.length[2]);
        window_info["length_used"] = py::make_tuple(used.length[0], used.length[1], used.length[2]);
        return py::make_tuple(fit::validation_json(v), curves, sigma_source, window_info);
      },
      py::arg("grid"), py::kw_only(), py::arg("sigma") = py::none(), py::arg("window") = "yarn",
      py::arg("axes") = "x,y,z", py::arg("rays_per_column") = 1, py::arg("seed") = 1, py::arg("models") = "all",
      py::arg("progress") = py::none(),
      "The validation's report (JSON text), its curves, sigma's and the window's source; use weft.validate.");
}

}  // namespace weft::python
