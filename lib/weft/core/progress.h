#pragma once
/// @file
/// @brief How library code reports progress without printing: the app supplies the sink.

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>

namespace weft {

/// @brief Receives progress of long computations; the `weft` app renders it as a terminal bar.
///
/// Calls to `advance` may come from several threads at once; implementations must be
/// thread-safe and cheap (a sink is free to throttle its own redraws).
class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  virtual void begin(std::string_view label, std::uint64_t total) = 0;
  virtual void advance(std::uint64_t done_so_far) = 0;
  virtual void end() = 0;
};

/// @brief A sink that ignores everything (the default for library callers and tests).
ProgressSink& null_progress();

/// @brief One stage of work with a known number of units, reported to a sink.
///
/// RAII: the destructor closes the stage. Thread-safe `step`.
class ProgressTask {
 public:
  ProgressTask(ProgressSink& sink, std::string_view label, std::uint64_t total);
  ~ProgressTask();
  ProgressTask(const ProgressTask&) = delete;
  ProgressTask& operator=(const ProgressTask&) = delete;

  void step(std::uint64_t units = 1);

 private:
  ProgressSink& sink_;
  std::atomic<std::uint64_t> done_{0};
};

}  // namespace weft
