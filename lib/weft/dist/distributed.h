#pragma once
/// @file
/// @brief Independent work units spread over MPI ranks, with results identical to one process.
///
/// A run is a set of units [0, n); unit u's work depends only on u (its RNG streams come from
/// stream_for(seed, u), docs/architecture.md §5), so where it runs cannot change its bytes. `run_units` assigns
/// the units to ranks statically and cyclically (rank k gets the k-th, (k+N)-th, … pending unit),
/// runs each rank's share on its TBB threads, gathers every unit's result bytes on rank 0 and
/// returns them there in unit order: the caller's reduction then sees exactly what a one-process
/// run sees. Without MPI (built without it, or not started by an MPI launcher) it is
/// parallel_units plus that ordering.
///
/// Why static: units are many and of similar cost (realizations, tiles × passes, sweep points in
/// groups), the assignment needs no coordinator (rank 0 computes like the others), and the same
/// command line always puts the same unit on the same rank, which keeps failures reproducible.
/// Cyclic, not blocks: neighbouring units often cost alike (a sweep's factors, an image's rows of
/// tiles), and interleaving spreads the expensive ones.
///
/// The work goes in rounds: each round every rank runs up to `batch` of its units, then one
/// gather brings the round's results and each rank's status to rank 0, which records them
/// (progress over all ranks; UnitStore for --resume) and broadcasts go on / stop. A unit that
/// throws on any rank thus stops every rank at the end of that round with the same UnitFailure
/// naming the unit — no rank waits for one that died.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/progress.h"

namespace weft::dist {

class UnitStore;

/// @brief A unit's result as bytes (callers encode it, e.g. nlohmann::json::to_msgpack).
using Bytes = std::vector<std::uint8_t>;

/// @brief The process's MPI session: `main` holds one for the program's lifetime.
///
/// Initializes MPI only when the process was started by an MPI launcher (mpirun/mpiexec of Open
/// MPI or MPICH, Slurm's srun with PMI/PMIx); otherwise, and in a build without MPI, rank() is 0
/// and size() is 1 and nothing else changes.
class Session {
 public:
  Session(int& argc, char**& argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// @brief Ends the run on every rank with one exit code and one error line, without hanging.
  ///
  /// `code` is this rank's result (0 ok) and `error_line` its `weft: error: …` line (empty if
  /// none, or if rank 0 speaks for it, as for a UnitFailure). Rank 0 prints its line; another
  /// rank prints its own only if rank 0 did not fail. Ranks that finished wait for the others; a
  /// rank that failed alone waits at most `failed_wait_seconds`, since the others may be inside
  /// run_units waiting for it, and then aborts the job (MPI_Abort). Returns the largest code.
  int finish(int code, const std::string& error_line, double failed_wait_seconds = 20.0);
};

/// @brief This process's rank, 0 … size()−1 (0 without MPI).
[[nodiscard]] int rank();
/// @brief The number of ranks (1 without MPI or without a launcher).
[[nodiscard]] int size();
/// @brief Whether this process writes outputs and prints (rank 0).
[[nodiscard]] inline bool is_root() { return rank() == 0; }
/// @brief "MPI (Open MPI 4.1.4)", or why there is none ("built without MPI", "not under mpirun").
[[nodiscard]] std::string describe();

/// @brief Rank 0's `value` on every rank (a collective: every rank calls it), for decisions that
/// must not differ between ranks, such as a time budget measured on rank 0's clock.
[[nodiscard]] bool root_decides(bool value);
/// @brief Rank 0's `value` on every rank, bit for bit (a collective), for numbers computed from
/// images that only rank 0 holds (e.g. the next step of a fit).
[[nodiscard]] double root_value(double value);
/// @brief Rank 0's `value` on every rank (a collective; other ranks' arguments are ignored), for
/// results gathered on rank 0 that every rank needs next (the render matrix's albedo factors),
/// without a file that would need a filesystem shared by the ranks.
[[nodiscard]] Bytes root_bytes(Bytes value);

/// @brief While one is alive, this process computes as if it ran alone: rank() is 0, size() is
/// 1, run_units keeps its units on this process and root_decides returns its argument.
///
/// For work units that are whole computations themselves (a case of the render-study matrix,
/// docs/render.md §6e, renders its images with render(), whose tiles are run_units of their
/// own): the unit's body opens one, so its nested collectives stay on this rank instead of
/// waiting for ranks that are busy with other units. The collective mode is untouched while no
/// scope is open. Scopes are counted over the process (TBB worker threads of the nested work
/// see them too), so units side by side on threads may each open one; the enclosing run_units
/// communicates only after its round's units returned, when every scope is closed.
class RankLocal {
 public:
  RankLocal();
  ~RankLocal();
  RankLocal(const RankLocal&) = delete;
  RankLocal& operator=(const RankLocal&) = delete;
};

/// @brief Thrown on every rank when a unit failed on some rank: the message names the unit.
class UnitFailure : public Error {
 public:
  UnitFailure(const std::string& message, bool internal) : Error(message), internal_(internal) {}
  /// The unit threw something other than weft::Error (an internal error, exit code 3).
  [[nodiscard]] bool internal() const { return internal_; }

 private:
  bool internal_;
};

struct UnitsOptions {
  /// Names unit u in errors ("sweep point 4 (+y, 1/4 of the rays)"); default "unit u".
  std::function<std::string(std::size_t)> name;
  /// Stepped on rank 0 with the units finished on all ranks (may be null).
  ProgressTask* progress = nullptr;
  /// 0: `progress` counts 1 per unit. > 0: it counts this many per unit, and the body steps it
  /// itself for the units its rank runs, as they go (ProgressShare: the study matrix's cases,
  /// docs/render.md §6e); run_units steps it for the units resumed and those other ranks finished.
  std::uint64_t unit_weight = 0;
  /// Rank 0 records each finished unit here and, on --resume, skips those it already holds.
  UnitStore* store = nullptr;
  /// On --resume, asked on rank 0 of each unit the store holds: false runs it again (a study
  /// matrix case whose folder was removed). Empty: every stored unit is taken.
  std::function<bool(std::size_t)> resumable;
  /// Units per rank per round; 0 = chosen from the unit count, the ranks and the threads.
  std::size_t batch = 0;
};

/// @brief Runs body(u) for u in [0, count) over all ranks; on rank 0 returns every unit's bytes in
/// unit order, elsewhere an empty vector. Every rank must call it with the same count (it is a
/// collective). Throws UnitFailure if a unit throws on any rank (on every rank).
///
/// Without a store (or when nothing was resumed) unit u runs on rank u mod size(), in every call:
/// a caller may keep per-unit state on the owning rank between calls (render's running sums).
///
/// Test hook (used by the CLI tests only): WEFT_TEST_FAIL_UNIT=u makes unit u throw on whichever
/// rank runs it; WEFT_TEST_KILL_AFTER_UNITS=k kills the process (SIGKILL, as a crash or a cluster's
/// time limit would) once rank 0 has recorded k units in the store in this run.
[[nodiscard]] std::vector<Bytes> run_units(std::size_t count, const std::function<Bytes(std::size_t unit)>& body,
                                           const UnitsOptions& options = {});

}  // namespace weft::dist
