#pragma once
// Shared helpers of the Python bindings: progress callbacks, GIL release, numpy conversions.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/progress.h"
#include "weft/transmittance/law.h"

namespace weft::python {

namespace py = pybind11;

void init_laws(py::module_& m);
void init_grid(py::module_& m);
void init_measure(py::module_& m);
void init_cloth(py::module_& m);
void init_render(py::module_& m);
void init_fibres(py::module_& m);

/// Thrown through library code (from a progress callback) to stop a long call when the Python
/// callback raised or the user pressed Ctrl-C; `run_released` re-raises the Python error.
struct CallbackAbort : std::exception {
  [[nodiscard]] const char* what() const noexcept override { return "weft: stopped by the progress callback"; }
};

/// @brief A ProgressSink that calls a Python callable `callback(label, done, total)`.
///
/// Library code reports from TBB worker threads; each report takes the GIL, and reports are
/// thinned to at most ~200 per stage so that progress does not slow the computation. A callback
/// that raises (and a pending KeyboardInterrupt) stops the computation at the next report.
class PyProgress final : public ProgressSink {
 public:
  explicit PyProgress(py::object callback) : callback_(std::move(callback)) {}
  ~PyProgress() override {
    py::gil_scoped_acquire gil;
    callback_ = py::object();
  }
  PyProgress(const PyProgress&) = delete;
  PyProgress& operator=(const PyProgress&) = delete;

  void begin(std::string_view label, std::uint64_t total) override {
    std::lock_guard lock(mutex_);
    label_ = std::string(label);
    total_ = total;
    last_ = 0;
    call(0);
  }
  void advance(std::uint64_t done) override {
    const std::uint64_t step = total_ / 200 + 1;
    if (done < last_.load(std::memory_order_relaxed) + step && done != total_) {
      check_stop();
      return;
    }
    std::lock_guard lock(mutex_);
    if (done <= last_ && done != total_) return;
    last_ = done;
    call(done);
  }
  void end() override {
    std::lock_guard lock(mutex_);
    call(total_);
  }

  /// Re-raises a stored Python error (after the GIL is held again).
  void rethrow_if_failed() {
    std::lock_guard lock(mutex_);
    if (error_) {
      auto e = std::move(*error_);
      error_.reset();
      throw e;
    }
  }

 private:
  void check_stop() const {
    if (stopped_.load(std::memory_order_relaxed)) throw CallbackAbort();
  }
  void call(std::uint64_t done) {
    if (stopped_.load()) throw CallbackAbort();
    py::gil_scoped_acquire gil;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!callback_.is_none()) callback_(label_, done, total_.load());
    } catch (py::error_already_set& e) {
      error_.emplace(std::move(e));
      stopped_ = true;
      throw CallbackAbort();
    }
  }

  py::object callback_;
  std::mutex mutex_;
  std::string label_;
  std::atomic<std::uint64_t> total_{0};
  std::atomic<std::uint64_t> last_{0};
  std::atomic<bool> stopped_{false};
  std::optional<py::error_already_set> error_;
};

/// @brief Runs `fn(progress_sink)` with the GIL released; a progress callback (or None) gets
/// reports. Errors of the callback are re-raised as themselves, weft::Error as weft.Error.
template <typename Fn>
auto run_released(const py::object& progress, Fn&& fn) {
  PyProgress sink(progress);
  try {
    py::gil_scoped_release release;
    return fn(static_cast<ProgressSink&>(sink));
  } catch (...) {
    // Library code may have wrapped the abort in its own error: the callback's error wins.
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

/// Parses an axis given as 0/1/2, "x"/"y"/"z" (signs allowed, direction sense ignored).
int axis_index(const py::object& axis, const char* what);

/// Converts a Python float, raising weft.Error (naming `what`) for NaN or infinity.
double finite(const char* what, double value);

}  // namespace weft::python
