#include "terminal_progress.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include <fmt/core.h>
#include <unistd.h>

#include "interrupt.h"

namespace weft::app {

TerminalProgress::TerminalProgress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO) != 0) {}

void TerminalProgress::begin(std::string_view label, std::uint64_t total) { begin_counting(label, total, {}); }

void TerminalProgress::begin_counting(std::string_view label, std::uint64_t total, std::string_view unit) {
  // Ctrl-C or SIGTERM stops the computation at its next report, drawn or not (apps/interrupt.h).
  stop_if_interrupted();
  if (!enabled_) return;
  const std::lock_guard lock(mutex_);
  label_ = std::string(label);
  unit_ = std::string(unit);
  total_ = total;
  last_done_ = 0;
  start_ = std::chrono::steady_clock::now();
  last_draw_ = start_;
  draw(0, false);
}

void TerminalProgress::advance(std::uint64_t done_so_far) {
  stop_if_interrupted();
  if (!enabled_) return;
  // Workers must never wait on the terminal: skip the redraw if another thread is drawing.
  const std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  last_done_ = std::max(last_done_, done_so_far);
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(last_done_, false);
}

void TerminalProgress::end() noexcept {
  if (!enabled_) return;
  // end() must not throw (it runs in destructors, docs/python.md "Interrupting a call"): a
  // final redraw that fails is dropped.
  // A stage a signal stopped ends where it stood ("stopped after"), not full.
  try {
    const std::lock_guard lock(mutex_);
    draw(interrupt_signal() != 0 ? last_done_ : total_, true);
  } catch (...) {
    return;
  }
}

std::string duration_text(double seconds) {
  if (!(seconds < 120.0)) {
    if (seconds < 2.0 * 3600.0) return fmt::format("{:.1f} min", seconds / 60.0);
    if (seconds < 2.0 * 86400.0) return fmt::format("{:.1f} h", seconds / 3600.0);
    if (seconds < 2.0 * 365.25 * 86400.0) return fmt::format("{:.0f} days", seconds / 86400.0);
    return fmt::format("{:.2g} years", seconds / (365.25 * 86400.0));
  }
  return fmt::format("{:.1f} s", seconds);
}

void TerminalProgress::draw(std::uint64_t done, bool final) {
  constexpr int kWidth = 30;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double fraction = total_ > 0 ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total_)) : 1.0;
  const int filled = static_cast<int>(fraction * kWidth);
  const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
  // Before the first unit is done there is no rate, so no estimate: "eta --", not "eta 0.0s".
  const std::string when =
      final      ? fmt::format("{} {:.1f}s", interrupt_signal() != 0 ? "stopped after" : "took", elapsed)
      : rate > 0 ? "eta " + duration_text(static_cast<double>(total_ - std::min(done, total_)) / rate)
                 : std::string("eta --");
  fmt::print(stderr, "\r{:<22} [{}{}] {:5.1f}% {:>10.3g} {}/s  {}\x1b[K", label_, std::string(filled, '#'),
             std::string(kWidth - filled, '.'), 100.0 * fraction, rate, unit_.empty() ? "units" : unit_, when);
  if (final) fmt::print(stderr, "\n");
  std::fflush(stderr);
}

}  // namespace weft::app
