#pragma once
/// @file
/// @brief Ctrl-C (SIGINT) and SIGTERM as a request to stop (docs/architecture.md "Progress and
/// cancellation").
///
/// The first such signal only records itself; the app's progress sink turns it into
/// weft::Cancelled at the computation's next report (and the points where a run commits its
/// outputs at theirs: set_stop_request, core/progress.h), so the stack unwinds like Python's
/// KeyboardInterrupt: atomic writes remove their temporaries, nothing half-written is left, and
/// the app exits 128 + the signal (130 for Ctrl-C, 143 for SIGTERM, as a shell reports them). A
/// second signal keeps its default action, so a stretch of work that reports nothing (a file
/// read, a large write) can still be killed at once.

#include <string_view>

namespace weft::app {

/// @brief While alive, the first SIGINT or SIGTERM is caught (one-shot handlers); restores the
/// previous actions when destroyed. Installed only when this process runs alone: under several
/// MPI ranks a rank stopping at its own next report could leave the others waiting in a
/// collective, so there both keep their default action (mpirun stops the job).
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
};

/// @brief The signal a live InterruptGuard caught (SIGINT or SIGTERM), 0 if none.
[[nodiscard]] int interrupt_signal() noexcept;

/// @brief Throws weft::Cancelled once interrupt_signal() is not 0.
void stop_if_interrupted();

/// @brief How the app ends after the signal stopped it: 128 + the signal, and the word for it
/// ("interrupted" for SIGINT, "terminated" for SIGTERM).
[[nodiscard]] int interrupted_exit_code(int signal) noexcept;
[[nodiscard]] std::string_view interrupted_word(int signal) noexcept;

}  // namespace weft::app
