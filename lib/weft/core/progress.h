#pragma once
/// @file
/// @brief How library code reports progress without printing (the app supplies the sink), and
/// how a caller stops a long computation at its next progress report (docs/python.md
/// "Interrupting a call").

#include <atomic>
#include <cstdint>
#include <exception>
#include <string>
#include <string_view>

namespace weft {

/// @brief Thrown by a ProgressSink (from `begin` or `advance`, never from `end`) to stop the
/// computation that reports to it: the user pressed Ctrl-C, or a callback failed.
///
/// It is not a weft::Error (nothing is wrong with the input) and library code must let it pass:
/// code that catches exceptions to add context catches weft::Error only, or rethrows Cancelled
/// unchanged. Work done in `tbb::parallel_for` bodies reaches the caller, because TBB cancels
/// the remaining iterations and rethrows the first exception in the calling thread. Nothing the
/// computation would have returned or written is produced.
class Cancelled : public std::exception {
 public:
  [[nodiscard]] const char* what() const noexcept override { return "weft: the computation was cancelled"; }
};

/// @brief Receives progress of long computations; the `weft` app renders it as a terminal bar.
///
/// Calls to `advance` may come from several threads at once (TBB workers and the caller's
/// thread); implementations must be thread-safe and cheap (a sink is free to throttle its own
/// redraws). `begin` and `advance` may throw Cancelled to stop the computation; once one call
/// has thrown, every later `advance` should throw too, so that all threads stop promptly. `end`
/// runs from a destructor (ProgressTask), also while a Cancelled unwinds the stack: it must not
/// throw.
class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  virtual void begin(std::string_view label, std::uint64_t total) = 0;
  /// `begin` with what a unit of `total` is ("rays"), for a sink that shows a rate; the default
  /// forgets it (Python's callback takes label, done, total).
  virtual void begin_counting(std::string_view label, std::uint64_t total, std::string_view /*unit*/) {
    begin(label, total);
  }
  virtual void advance(std::uint64_t done_so_far) = 0;
  virtual void end() noexcept = 0;
};

/// @brief Registers the flag a signal handler sets to ask the process to stop (apps/interrupt.h),
/// or none (nullptr). Library code reads it only where a run commits its outputs, so a request
/// that arrived during a stretch that reports no progress (drawing a plot, writing a file) still
/// stops the run before its outputs replace anything.
void set_stop_request(const std::atomic<int>* flag) noexcept;

/// @brief Throws Cancelled when the registered flag (set_stop_request) is set.
void stop_if_requested();

/// @brief A sink that ignores everything (the default for library callers and tests).
ProgressSink& null_progress();

/// @brief One stage of work with a known number of units, reported to a sink.
///
/// RAII: the destructor closes the stage (and never throws). Thread-safe `step`, which throws
/// Cancelled when the sink asks to stop: call it where an exception may leave the computation
/// (in a TBB body, never in a destructor, a noexcept function or a thread of your own).
class ProgressTask {
 public:
  ProgressTask(ProgressSink& sink, std::string_view label, std::uint64_t total);
  /// A stage whose units are `unit` ("rays"): a terminal shows the rate as "… rays/s".
  ProgressTask(ProgressSink& sink, std::string_view label, std::uint64_t total, std::string_view unit);
  ~ProgressTask();
  ProgressTask(const ProgressTask&) = delete;
  ProgressTask& operator=(const ProgressTask&) = delete;

  void step(std::uint64_t units = 1);

 private:
  ProgressSink& sink_;
  std::atomic<std::uint64_t> done_{0};
};

/// @brief Shows an inner computation as a share of an outer stage (docs/render.md §6e: the study
/// matrix's cases, a study's renders): every stage begun on this sink (with `only` given, every
/// stage of that label; others count nothing) moves `outer` by `weight` units, in proportion to
/// its progress as it goes. A stage's unreported rest is stepped at the next `begin` or `finish`.
/// Every `begin` and `advance` steps `outer`, so the outer sink's Cancelled stops the inner
/// computation at its next report. Thread-safe like ProgressTask.
class ProgressShare final : public ProgressSink {
 public:
  ProgressShare(ProgressTask& outer, std::uint64_t weight, std::string only = {});
  void begin(std::string_view label, std::uint64_t total) override;
  void advance(std::uint64_t done_so_far) override;
  void end() noexcept override {}
  /// Steps `outer` to `weight` × the counted stages begun so far (may throw Cancelled).
  void finish();

 private:
  /// Steps `outer` up to `target` units of this share (never back), or by 0 to let it stop us.
  void reach(std::uint64_t target);

  ProgressTask& outer_;
  std::uint64_t weight_;
  std::string only_;
  std::atomic<bool> counting_{false};
  std::atomic<std::uint64_t> total_{0};
  std::atomic<std::uint64_t> stages_{0};   ///< counted stages begun
  std::atomic<std::uint64_t> counted_{0};  ///< units stepped on `outer` so far
};

}  // namespace weft
