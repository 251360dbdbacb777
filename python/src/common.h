#pragma once
// Shared helpers of the Python bindings: progress callbacks, GIL release, numpy conversions.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/progress.h"
#include "weft/transmittance/law.h"
#include "weft/volume/grid.h"
#include "weft/volume/provenance.h"

namespace weft::python {

namespace py = pybind11;

void init_laws(py::module_& m);
void init_grid(py::module_& m);
void init_measure(py::module_& m);
void init_cloth(py::module_& m);
void init_render(py::module_& m);
void init_fibres(py::module_& m);
void init_study(py::module_& m);

/// σ of a grid call, by the one rule of volume::resolve_sigma: values that are extinction
/// (weft:value_kind) → 1; else `sigma=` when given (checked > 0, the error naming `call`); else the
/// grid's provenance; else weft::Error asking for sigma=, never a silent σ = 1.
[[nodiscard]] volume::SigmaChoice grid_sigma(const volume::Grid& grid, const std::optional<double>& sigma,
                                             const char* call);

/// @brief A ProgressSink that calls a Python callable `callback(label, done, total)` and stops the
/// computation (weft::Cancelled, docs/python.md "Interrupting a call") when the callback raised or
/// Ctrl-C was pressed.
///
/// Library code reports from TBB workers and from the calling thread; a report takes the GIL, and
/// reports are thinned to at most ~200 per stage so that progress does not slow the computation.
/// Python runs signal handlers only in the main thread, so the calling thread also looks for a
/// pending Ctrl-C every ~50 ms of its own reports. The Python error is kept and re-raised by
/// run_released once the GIL is held again; `end` never throws (it runs in destructors).
class PyProgress final : public ProgressSink {
 public:
  explicit PyProgress(py::object callback)
      : callback_(std::move(callback)), caller_(std::this_thread::get_id()), last_signal_check_(Clock::now()) {
    // Refused before the work starts, not at its first report (weft/_arguments.py names the call).
    if (!callback_.is_none() && PyCallable_Check(callback_.ptr()) == 0)
      throw py::type_error("progress must be a callable(label, done, total), True or None, got " +
                           py::str(py::type::of(callback_).attr("__name__")).cast<std::string>());
  }
  ~PyProgress() override {
    py::gil_scoped_acquire gil;
    callback_ = py::object();
  }
  PyProgress(const PyProgress&) = delete;
  PyProgress& operator=(const PyProgress&) = delete;

  void begin(std::string_view label, std::uint64_t total) override {
    throw_if_stopped();
    std::lock_guard lock(mutex_);
    label_ = std::string(label);
    total_ = total;
    last_ = 0;
    report(0);
  }
  void advance(std::uint64_t done) override {
    throw_if_stopped();
    const std::uint64_t step = total_ / 200 + 1;
    if (done < last_.load(std::memory_order_relaxed) + step && done != total_) {
      if (std::this_thread::get_id() == caller_ && Clock::now() - last_signal_check_ > std::chrono::milliseconds(50)) {
        std::lock_guard lock(mutex_);
        last_signal_check_ = Clock::now();
        report(std::nullopt);
      }
      return;
    }
    std::lock_guard lock(mutex_);
    if (done <= last_ && done != total_) return;
    last_ = done;
    report(done);
  }
  void end() noexcept override {
    if (stopped_.load()) return;
    try {
      std::lock_guard lock(mutex_);
      report(total_.load());
    } catch (...) {
      // report() kept the callback's error (or Ctrl-C) for rethrow_if_failed; the stage is over.
      return;
    }
  }

  /// Re-raises a kept Python error (call with the GIL held).
  void rethrow_if_failed() {
    std::lock_guard lock(mutex_);
    if (error_) {
      auto e = std::move(*error_);
      error_.reset();
      throw e;
    }
  }

 private:
  using Clock = std::chrono::steady_clock;

  void throw_if_stopped() const {
    if (stopped_.load(std::memory_order_relaxed)) throw Cancelled();
  }
  /// Runs pending signal handlers (Ctrl-C raises KeyboardInterrupt there) and, for a `done`
  /// count, the callback; a Python error is kept and stops the computation. Holds mutex_.
  void report(std::optional<std::uint64_t> done) {
    throw_if_stopped();
    py::gil_scoped_acquire gil;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (done && !callback_.is_none()) callback_(label_, *done, total_.load());
    } catch (py::error_already_set& e) {
      error_.emplace(std::move(e));
      stopped_ = true;
      throw Cancelled();
    }
  }

  py::object callback_;
  std::thread::id caller_;
  std::mutex mutex_;
  std::string label_;
  std::atomic<std::uint64_t> total_{0};
  std::atomic<std::uint64_t> last_{0};
  std::atomic<bool> stopped_{false};
  Clock::time_point last_signal_check_;  // only the calling thread touches it
  std::optional<py::error_already_set> error_;
};

/// @brief Runs `fn()`; a weft::Error it throws is raised with the called function's name `call`
/// in front, once (docs/python.md "API": every message of a call starts with its name, never
/// another call's or none): "measure_fields_beam: local-gamma fields 'f.vdb': …". Cancelled and
/// Python's own exceptions pass unchanged.
template <typename Fn>
decltype(auto) in_call(const char* call, Fn&& fn) {
  try {
    return std::forward<Fn>(fn)();
  } catch (const Error& e) {
    const std::string head = std::string(call) + ": ";
    const std::string message = e.what();
    if (message.rfind(head, 0) == 0) throw;
    throw Error(head + message);
  }
}

/// @brief A binding `f` (a non-generic lambda) whose weft::Error comes out through in_call(call):
/// `m.def("measure_beam", named_call("measure_beam", [](…) {…}), …)`.
template <typename F, typename R, typename... A>
auto named_call_impl(const char* call, F f, R (F::*)(A...) const) {
  return [call, f = std::move(f)](A... args) -> R {
    return in_call(call, [&]() -> R { return f(std::forward<A>(args)...); });
  };
}
template <typename F>
auto named_call(const char* call, F f) {
  return named_call_impl(call, std::move(f), &F::operator());
}

/// @brief Runs `fn(progress_sink)` with the GIL released; a progress callback (or None) gets
/// reports. The callback's exception (or KeyboardInterrupt) is re-raised as itself, also when it
/// came from the last report of a computation that had finished; weft::Error as weft.Error.
template <typename Fn>
auto run_released(const py::object& progress, Fn&& fn) {
  PyProgress sink(progress);
  try {
    auto result = [&] {
      py::gil_scoped_release release;
      return fn(static_cast<ProgressSink&>(sink));
    }();
    sink.rethrow_if_failed();
    return result;
  } catch (...) {
    // Library code may have wrapped the stop in its own error: the callback's error wins.
    sink.rethrow_if_failed();
    throw;
  }
}

/// A 1-D numpy array owning a copy of `values`.
template <typename T>
py::array_t<T> to_array(const std::vector<T>& values) {
  py::array_t<T> a(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

/// A 1-D numpy array that takes over `values` without copying.
template <typename T>
py::array_t<T> move_to_array(std::vector<T>&& values) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({static_cast<py::ssize_t>(owned->size())}, {static_cast<py::ssize_t>(sizeof(T))}, owned->data(),
                        free_when_done);
}

/// Laws are immutable; pybind11 holders cannot be shared_ptr<const T>, so Python holds them as
/// shared_ptr<Law> and never calls a non-const member.
using PyLaw = std::shared_ptr<transmittance::Law>;
inline PyLaw py_law(const transmittance::LawPtr& law) { return std::const_pointer_cast<transmittance::Law>(law); }

/// weft.Warning, the category of every warning the module raises (a UserWarning subclass; made
/// by the module's init).
PyObject* warning_category();
/// Raises each line as a weft.Warning "<call>: <line>" (with the GIL held), at the caller's line.
void warn_all(const std::vector<std::string>& warnings, const char* call);

/// Whether `value` is a number: Python's and NumPy's alike (numbers.Real, where NumPy registers its
/// scalars: np.float32(0.5) and np.int64(1) are numbers as 0.5 and 1 are), never a bool.
bool is_real_number(const py::handle& value);
/// The same for integers (numbers.Integral: int, np.int64, ...), never a bool.
bool is_integer_number(const py::handle& value);

/// Parses an axis given as 0/1/2, "x"/"y"/"z" (signs allowed, direction sense ignored).
int axis_index(const py::object& axis, const char* what);

/// A path argument (a str or an os.PathLike) as text; anything else is a TypeError naming `what`
/// (e.g. "Grid.save: path"), which weft/_arguments.py raises as weft.ArgumentTypeError.
std::string path_arg(const py::object& path, const char* what);

/// The same for the path of an output (`folder`: a folder, else a file): an empty or blank one is a
/// weft.Error "<what>: must name a file, got an empty value" (weft::output_name_problem, the CLI's
/// rule), not a write to the working folder or a failed rename of a temporary file.
std::string output_path_arg(const py::object& path, const char* what, bool folder);

/// An argument a binding takes as a Python object, converted to T; a value pybind11 cannot convert
/// is a TypeError "<what> must be <expected>, got <type>" (weft.ArgumentTypeError in Python), not
/// pybind11's cast error, which names neither.
template <typename T>
T arg_cast(const py::handle& value, const char* what, const char* expected) {
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    throw py::type_error(std::string(what) + " must be " + expected + ", got " +
                         py::str(py::type::of(value).attr("__name__")).cast<std::string>());
  }
}

/// Converts a Python float, raising weft.Error (naming `what`) for NaN or infinity.
double finite(const char* what, double value);

}  // namespace weft::python
