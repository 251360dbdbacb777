#pragma once
/// @file
/// @brief Wall and process-CPU seconds of consecutive stages of a run: CPU counts every thread,
/// so a stage's CPU compares with another's whatever the thread count (docs/benchmarks.md).

#include <chrono>
#include <ctime>

namespace weft {

class StageClock {
 public:
  StageClock() { restart(); }
  void restart() {
    wall0_ = std::chrono::steady_clock::now();
    cpu0_ = std::clock();
  }
  /// Seconds since the last lap (or the start) into `wall` and `cpu`; the next stage starts now.
  void lap(double& wall, double& cpu) {
    const auto now = std::chrono::steady_clock::now();
    const std::clock_t c = std::clock();
    wall = std::chrono::duration<double>(now - wall0_).count();
    cpu = static_cast<double>(c - cpu0_) / CLOCKS_PER_SEC;
    wall0_ = now;
    cpu0_ = c;
  }

 private:
  std::chrono::steady_clock::time_point wall0_;
  std::clock_t cpu0_ = 0;
};

}  // namespace weft
