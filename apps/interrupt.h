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

/// @brief From now until the process exits, the first SIGINT or SIGTERM is caught (one-shot
/// handlers). Not restored at the end of the run: a signal between a run's last commit and the
/// exit would otherwise kill the process by the default action, its outputs new and complete but
/// its exit code 130 and its buffered `wrote` lines lost; caught, it is too late to stop anything
/// and the run reports its success. Installed only when this process runs alone: under several
/// MPI ranks a rank stopping at its own next report could leave the others waiting in a
/// collective, so there both keep their default action (mpirun stops the job).
void catch_interrupts();

/// @brief The signal caught since catch_interrupts (SIGINT or SIGTERM), 0 if none.
[[nodiscard]] int interrupt_signal() noexcept;

/// @brief Throws weft::Cancelled once interrupt_signal() is not 0.
void stop_if_interrupted();

/// @brief How the app ends after the signal stopped it: 128 + the signal, and the word for it
/// ("interrupted" for SIGINT, "terminated" for SIGTERM).
[[nodiscard]] int interrupted_exit_code(int signal) noexcept;
[[nodiscard]] std::string_view interrupted_word(int signal) noexcept;

}  // namespace weft::app
