#pragma once
/// @file
/// @brief A progress bar with rate and ETA on a terminal; silent when stderr is not a TTY. Either
/// way it stops the computation with weft::Cancelled once Ctrl-C or SIGTERM came (apps/interrupt.h).

#include <chrono>
#include <memory>
#include <mutex>
#include <string>

#include "weft/core/progress.h"

namespace weft::app {

/// @brief A duration for a person: "42.0 s", "12.5 min", "3.2 h", "58 days", "1.6e+03 years"
/// (an estimate said before a run, a progress bar's ETA).
[[nodiscard]] std::string duration_text(double seconds);

class TerminalProgress final : public ProgressSink {
 public:
  /// `enabled` false (or stderr not a terminal) makes every call a no-op.
  explicit TerminalProgress(bool enabled);
  void begin(std::string_view label, std::uint64_t total) override;
  void begin_counting(std::string_view label, std::uint64_t total, std::string_view unit) override;
  void advance(std::uint64_t done_so_far) override;
  void end() noexcept override;

 private:
  void draw(std::uint64_t done, bool final);

  bool enabled_;
  std::mutex mutex_;
  std::string label_;
  std::string unit_;  ///< what the rate counts ("rays"), or "" (units)
  std::uint64_t total_ = 0;
  std::uint64_t last_done_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace weft::app
