// The Python module weft._weft (pybind11): the library's laws, grids, ground truth, fits, cloth
// generator and renderer. python/weft/__init__.py re-exports it with the dict-taking helpers.
#include <cmath>
#include <string>

#include <tbb/global_control.h>

#include "common.h"
#include "weft/core/atomic_file.h"
#include "weft/core/parallel.h"
#include "weft/render/render.h"
#include "weft/volume/beam.h"

namespace weft::python {

namespace {
bool is_bool(const py::handle& value) {
  // NumPy's np.bool_ is no Python bool, but as much a flag.
  return py::isinstance<py::bool_>(value) ||
         py::str(py::type::of(value).attr("__name__")).cast<std::string>() == "bool_";
}
bool is_instance_of(const py::handle& value, const char* abc) {
  const int r = PyObject_IsInstance(value.ptr(), py::module_::import("numbers").attr(abc).ptr());
  if (r < 0) throw py::error_already_set();
  return r == 1;
}
}  // namespace

bool is_real_number(const py::handle& value) { return !is_bool(value) && is_instance_of(value, "Real"); }
bool is_integer_number(const py::handle& value) { return !is_bool(value) && is_instance_of(value, "Integral"); }

int axis_index(const py::object& axis, const char* what) {
  // `what` names the call and the argument ("window_stats: axis"): said once, not "axis: axis".
  if (is_bool(axis)) throw py::type_error(std::string(what) + " must be 0, 1, 2 or 'x', 'y', 'z', got bool");
  if (is_integer_number(axis)) {
    const long a = arg_cast<long>(py::int_(axis), what, "0, 1 or 2");
    if (a < 0 || a > 2) fail("{} must be 0, 1 or 2, got {}", what, a);
    return static_cast<int>(a);
  }
  if (py::isinstance<py::str>(axis)) {
    const auto text = axis.cast<std::string>();
    int a = -1;
    try {
      a = volume::beam_axis(volume::parse_direction(text));
    } catch (const Error&) {
      a = -1;
    }
    if (a < 0) fail("{} must be 0, 1, 2 or 'x', 'y', 'z', got '{}'", what, text);
    return a;
  }
  throw py::type_error(std::string(what) + " must be 0, 1, 2 or 'x', 'y', 'z', got " +
                       py::str(py::type::of(axis)).cast<std::string>());
}

double finite(const char* what, double value) { return require_finite(what, value); }

std::string path_arg(const py::object& path, const char* what) {
  if (!py::isinstance<py::str>(path) && !py::isinstance<py::bytes>(path) && !py::hasattr(path, "__fspath__"))
    throw py::type_error(std::string(what) + " must be a str, bytes or os.PathLike, got " +
                         py::str(py::type::of(path).attr("__name__")).cast<std::string>());
  // os.fsdecode: a bytes path (or a PathLike giving bytes) in the filesystem's encoding, as open() takes it.
  return py::module_::import("os").attr("fsdecode")(path).cast<std::string>();
}

std::string output_path_arg(const py::object& path, const char* what, bool folder) {
  std::string text = path_arg(path, what);
  if (const std::string problem = output_name_problem(text, folder); !problem.empty()) fail("{}: {}", what, problem);
  return text;
}

PyObject* warning_category() {
  // Made once with the module and kept for the interpreter's life (as pybind11 keeps its
  // exception types), so warnings from any binding share one class.
  static PyObject* category = PyErr_NewExceptionWithDoc(
      "weft.Warning",
      "What weft does but you probably did not mean (e.g. a scene medium that cannot affect the image); a "
      "UserWarning.",
      PyExc_UserWarning, nullptr);
  return category;
}

void warn_all(const std::vector<std::string>& warnings, const char* call) {
  for (const std::string& w : warnings) {
    if (PyErr_WarnEx(warning_category(), (std::string(call) + ": " + w).c_str(), 2) != 0) throw py::error_already_set();
  }
}

}  // namespace weft::python

PYBIND11_MODULE(_weft, m) {
  namespace py = pybind11;
  m.doc() =
      "weft: transmittance of correlated media (cloth) - laws, voxel grids, ground truth by DDA,\n"
      "gamma fits, the procedural cloth generator and the volumetric path tracer (docs/python.md).";
  // One Python exception for every bad input: its message is weft's one-line error text.
  static py::exception<weft::Error> error(m, "Error");
  error.doc() = "Raised for bad input and impossible requests; the message names the input and the problem.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const weft::Error& e) {
      error(e.what());
    } catch (const weft::Cancelled& e) {
      // Only reached when the stop had no Python error behind it (run_released re-raises that).
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });
  PyObject* warning = weft::python::warning_category();
  if (warning == nullptr) throw py::error_already_set();
  m.attr("Warning") = py::reinterpret_borrow<py::object>(warning);
  // threads= of the long calls (python/weft/__init__.py): TBB's pool limited while `fn` runs, as
  // the CLI's --threads does; outputs do not depend on it (docs/architecture.md §5).
  m.def(
      "_with_threads",
      [](unsigned threads, const py::function& fn) {
        const weft::ThreadLimit limit(threads);
        return fn();
      },
      py::arg("threads"), py::arg("fn"));
  // The library's ranges, for the checks in weft/__init__.py that run before pybind11 would turn
  // an out-of-range int into a TypeError naming the private binding.
  m.attr("_max_threads") = weft::kMaxThreads;
  m.attr("_max_spp") = weft::render::kMaxSpp;
  // out= and path= of the calls written in Python (weft/_study.py, plot_validation): the CLI's rule
  // for an output name (weft::output_name_problem), one weft.Error "<what>: must name a folder, ...".
  m.def(
      "_check_output_name",
      [](const py::object& path, const char* what, bool folder) {
        (void)weft::python::output_path_arg(path, what, folder);
      },
      py::arg("path"), py::arg("what"), py::arg("folder"));
  m.def("_thread_limit",
        [] { return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism); });
  weft::python::init_laws(m);
  weft::python::init_grid(m);
  weft::python::init_measure(m);
  weft::python::init_cloth(m);
  weft::python::init_render(m);
  weft::python::init_fibres(m);
  weft::python::init_study(m);
}
