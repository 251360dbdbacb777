#pragma once
/// @file
/// @brief Ctrl-C as a request to stop (docs/architecture.md "Progress and cancellation").
///
/// The first SIGINT only sets a flag; the app's progress sink turns it into weft::Cancelled at
/// the computation's next report, so the stack unwinds like Python's KeyboardInterrupt: atomic
/// writes remove their temporaries, nothing half-written is left, and the app exits 130 (the
/// shell's code for a SIGINT). A second SIGINT keeps its default action, so a stretch of work
/// that reports nothing (a file read, a large write) can still be killed at once.

namespace weft::app {

/// @brief While alive, the first SIGINT is caught (a one-shot handler); restores the previous
/// action when destroyed. Installed only when this process runs alone: under several MPI ranks a
/// rank stopping at its own next report could leave the others waiting in a collective, so
/// there SIGINT keeps its default action (mpirun stops the job).
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
};

/// @brief True once a SIGINT was caught by a live InterruptGuard (async-signal-safe to set).
[[nodiscard]] bool interrupt_requested() noexcept;

/// @brief Throws weft::Cancelled if interrupt_requested().
void stop_if_interrupted();

/// @brief The exit code of a run stopped by Ctrl-C: 128 + SIGINT, as a shell reports it.
inline constexpr int kInterruptedExitCode = 130;

}  // namespace weft::app
