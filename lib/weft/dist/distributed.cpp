// Work units over MPI ranks (distributed.h). The only file of weft that includes <mpi.h>.
#include "weft/dist/distributed.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/core.h>
#include <tbb/global_control.h>

#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/dist/unit_store.h"

#if WEFT_HAVE_MPI
#include <mpi.h>
#endif

namespace weft::dist {
namespace {

int g_rank = 0;
int g_size = 1;
/// Open RankLocal scopes: while > 0 this process acts as a one-process run (rank(), size(), the
/// collectives below). Atomic: units side by side on threads open and close their own scopes.
std::atomic<int> g_local{0};
bool g_mpi = false;  // MPI_Init was called by this process's Session
#if WEFT_HAVE_MPI
std::string g_describe = "not started by an MPI launcher (one process)";
#else
std::string g_describe = "built without MPI (one process)";
#endif

#if WEFT_HAVE_MPI
/// Launchers announce themselves in the environment: Open MPI's mpirun, MPICH's Hydra (PMI-1),
/// and PMI-2/PMIx launchers such as Slurm's srun. A plain `weft` run stays a plain process
/// (no singleton MPI start-up, no network probing).
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_RANK", "PMI_SIZE", "PMIX_RANK"}) {
    if (std::getenv(v) != nullptr) return true;
  }
  return false;
}
#endif

std::optional<std::size_t> env_index(const char* name) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return std::nullopt;
  char* end = nullptr;
  const unsigned long long x = std::strtoull(v, &end, 10);
  if (end == v || *end != '\0') return std::nullopt;
  return static_cast<std::size_t>(x);
}

// A round's message of one rank: status, the first failure, then (unit, bytes) pairs. Fixed-width
// host-order integers: every rank of a job runs the same binary on the same architecture.
void put_u64(Bytes& b, std::uint64_t x) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&x);
  b.insert(b.end(), p, p + sizeof x);
}
void put_bytes(Bytes& b, const std::uint8_t* data, std::size_t n) {
  put_u64(b, n);
  b.insert(b.end(), data, data + n);
}
struct Reader {
  const Bytes& b;
  std::size_t at = 0;
  std::uint64_t u64() {
    std::uint64_t x = 0;
    if (at + sizeof x > b.size()) throw Error("distributed run: truncated round message");
    std::memcpy(&x, b.data() + at, sizeof x);
    at += sizeof x;
    return x;
  }
  Bytes bytes() {
    const std::uint64_t n = u64();
    if (at + n > b.size()) throw Error("distributed run: truncated round message");
    Bytes out(b.begin() + static_cast<std::ptrdiff_t>(at), b.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
    return out;
  }
};

/// This thread's CPU time: a unit's cost where wall time is inflated by other processes on a shared
/// machine (its whole cost with --threads 1; nested parallel work on other threads is not in it).
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// WEFT_UNIT_COSTS=<file>: rank 0 appends one CSV row per unit (rank, wall seconds, result bytes,
/// thread CPU seconds) and per round (wall seconds from entering the gather to the decision, bytes
/// gathered, rank 0's CPU seconds meanwhile), the measured inputs of the scaling model in
/// docs/scale-out.md. A benchmark aid, not an output.
struct CostLog {
  std::FILE* f = nullptr;
  static inline int run = 0;
  int id;
  explicit CostLog(const char* path) : f(std::fopen(path, "a")), id(run++) {
    if (f != nullptr && std::ftell(f) == 0) std::fputs("run,kind,index,rank,ranks,seconds,bytes,cpu_seconds\n", f);
  }
  ~CostLog() {
    if (f != nullptr) std::fclose(f);
  }
  CostLog(const CostLog&) = delete;
  CostLog& operator=(const CostLog&) = delete;
  void unit(std::uint64_t u, std::size_t r, double seconds, std::size_t bytes, double cpu) const {
    if (f != nullptr) fmt::print(f, "{},unit,{},{},{},{:.6g},{},{:.6g}\n", id, u, r, g_size, seconds, bytes, cpu);
  }
  void round(std::size_t index, double seconds, std::size_t bytes, double cpu) const {
    if (f != nullptr) fmt::print(f, "{},round,{},0,{},{:.6g},{},{:.6g}\n", id, index, g_size, seconds, bytes, cpu);
  }
};

enum Status : std::uint64_t { kOk = 0, kFailed = 1, kInternal = 2 };

#if WEFT_HAVE_MPI
/// Waits for a non-blocking collective without spinning. MPI's blocking collectives busy-poll:
/// a rank that finished its round early burns a core until the slowest rank arrives, which on a
/// shared or oversubscribed machine (more ranks than cores, as in the CI tests and
/// scripts/bench_mpi) takes that core from the ranks still computing and doubled the CPU time of
/// `mpirun -n 2` on 2 cores. Polling with a growing sleep (10 µs … 1 ms) gives the core away;
/// it adds at most ~1 ms per collective, against rounds that last seconds (≤ ~32 per run).
void wait_gently(MPI_Request& request) {
  int done = 0;
  auto pause = std::chrono::microseconds(10);
  while (true) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done != 0) return;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(1000));
  }
}
#endif

/// Every rank's message on rank 0 (index = rank); other ranks get an empty vector.
std::vector<Bytes> gather_to_root(const Bytes& mine) {
#if WEFT_HAVE_MPI
  if (size() > 1) {
    // Counts are ints in MPI: a round's message above 2 GiB is refused before anything is sent.
    if (mine.size() > static_cast<std::size_t>(INT_MAX)) throw Error("distributed run: a round's results exceed 2 GiB");
    int n = static_cast<int>(mine.size());
    std::vector<int> counts(rank() == 0 ? static_cast<std::size_t>(size()) : 0);
    MPI_Request request = MPI_REQUEST_NULL;
    MPI_Igather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
    wait_gently(request);
    std::vector<int> displs(counts.size());
    Bytes all;
    if (rank() == 0) {
      long long total = 0;
      for (std::size_t r = 0; r < counts.size(); ++r) {
        displs[r] = static_cast<int>(total);
        total += counts[r];
      }
      if (total > INT_MAX) throw Error("distributed run: a round's results exceed 2 GiB on rank 0");
      all.resize(static_cast<std::size_t>(total));
    }
    MPI_Igatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0, MPI_COMM_WORLD,
                 &request);
    wait_gently(request);
    std::vector<Bytes> out;
    for (std::size_t r = 0; r < counts.size(); ++r) {
      out.emplace_back(all.begin() + displs[r], all.begin() + displs[r] + counts[r]);
    }
    return out;
  }
#endif
  return {mine};
}

/// Rank 0's `b` on every rank.
void broadcast(Bytes& b) {
#if WEFT_HAVE_MPI
  if (size() > 1) {
    unsigned long long n = b.size();
    MPI_Request request = MPI_REQUEST_NULL;
    MPI_Ibcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD, &request);
    wait_gently(request);
    if (n > static_cast<unsigned long long>(INT_MAX)) std::abort();  // rank 0 never sends that much
    b.resize(static_cast<std::size_t>(n));
    MPI_Ibcast(b.data(), static_cast<int>(n), MPI_BYTE, 0, MPI_COMM_WORLD, &request);
    wait_gently(request);
  }
#else
  (void)b;
#endif
}

struct Decision {
  std::uint64_t status = kOk;
  std::string message;
};

/// Rank 0's decision (go on, or stop with a message) on every rank.
Decision broadcast(const Decision& d) {
  Bytes b;
  if (rank() == 0) {
    put_u64(b, d.status);
    put_bytes(b, reinterpret_cast<const std::uint8_t*>(d.message.data()), d.message.size());
  }
  broadcast(b);
  Reader r{b};
  Decision out;
  out.status = r.u64();
  const Bytes m = r.bytes();
  out.message.assign(m.begin(), m.end());
  return out;
}

}  // namespace

Session::Session(int& argc, char**& argv) {
#if WEFT_HAVE_MPI
  if (!launched_by_mpi()) return;
  int provided = 0;
  // Only the main thread calls MPI (TBB's workers never do): FUNNELED is enough.
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  g_mpi = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  char version[MPI_MAX_LIBRARY_VERSION_STRING] = {};
  int len = 0;
  MPI_Get_library_version(version, &len);
  std::string v(version, static_cast<std::size_t>(std::max(len, 0)));
  v = v.substr(0, v.find_first_of(",\n"));
  g_describe = fmt::format("MPI, {} rank(s) ({})", g_size, v);
#else
  (void)argc;
  (void)argv;
#endif
}

Session::~Session() {
#if WEFT_HAVE_MPI
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (g_mpi && finalized == 0) MPI_Finalize();
#endif
}

int Session::finish(int code, const std::string& error_line, double failed_wait_seconds) {
  if (g_size == 1) {
    if (!error_line.empty()) fmt::print(stderr, "{}\n", error_line);
    return code;
  }
#if WEFT_HAVE_MPI
  // Rank 0 speaks for the run; other ranks print only what rank 0 cannot know.
  if (g_rank == 0 && !error_line.empty()) fmt::print(stderr, "{}\n", error_line);
  int send[2] = {g_rank == 0 ? code : 0, code};
  int recv[2] = {0, 0};
  MPI_Request request = MPI_REQUEST_NULL;
  MPI_Iallreduce(send, recv, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD, &request);
  if (code == 0) {
    wait_gently(request);  // rank 0 may still be writing outputs: sleep, not spin
  } else {
    // A rank that failed alone may have left the others inside run_units, waiting for it.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(failed_wait_seconds);
    int done = 0;
    while (MPI_Test(&request, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && done == 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        if (g_rank != 0 && !error_line.empty()) fmt::print(stderr, "{} (rank {})\n", error_line, g_rank);
        std::fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, code);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  if (g_rank != 0 && recv[0] == 0 && !error_line.empty()) fmt::print(stderr, "{} (rank {})\n", error_line, g_rank);
  return recv[1];
#else
  return code;
#endif
}

bool root_decides(bool value) {
  if (g_local.load() > 0) return value;
  Bytes b{static_cast<std::uint8_t>(value ? 1 : 0)};
  broadcast(b);
  return b.at(0) != 0;
}

double root_value(double value) {
  Bytes b(sizeof value);
  std::memcpy(b.data(), &value, sizeof value);
  broadcast(b);
  std::memcpy(&value, b.data(), sizeof value);
  return value;
}

Bytes root_bytes(Bytes value) {
  broadcast(value);
  return value;
}

int rank() { return g_local.load() > 0 ? 0 : g_rank; }
int size() { return g_local.load() > 0 ? 1 : g_size; }

RankLocal::RankLocal() { g_local.fetch_add(1); }
RankLocal::~RankLocal() { g_local.fetch_sub(1); }
std::string describe() { return g_describe; }

std::vector<Bytes> run_units(std::size_t count, const std::function<Bytes(std::size_t)>& body,
                             const UnitsOptions& options) {
  const bool root = rank() == 0;
  const auto name = [&](std::size_t u) { return options.name ? options.name(u) : fmt::format("unit {}", u); };
  const std::optional<std::size_t> fail_unit = env_index("WEFT_TEST_FAIL_UNIT");
  const std::optional<std::size_t> kill_after = env_index("WEFT_TEST_KILL_AFTER_UNITS");
  std::vector<Bytes> results(root ? count : 0);
  std::optional<CostLog> costs;
  if (const char* path = std::getenv("WEFT_UNIT_COSTS");
      root && g_local.load() == 0 && path != nullptr && *path != '\0')
    costs.emplace(path);

  // Rank 0 opens the store and lists the units still to do; every rank learns the list.
  Bytes plan;
  Decision setup;
  if (root) {
    try {
      std::vector<bool> have(count, false);
      std::size_t found = 0;
      if (options.store != nullptr) {
        options.store->open();
        if (options.store->resume()) {
          for (std::size_t u = 0; u < count; ++u) {
            // A stored unit whose outputs outside the store are gone is run again.
            if (options.resumable && !options.resumable(u)) continue;
            if (auto b = options.store->load(u)) {
              results[u] = std::move(*b);
              have[u] = true;
              ++found;
            }
          }
        }
        options.store->set_found(found);
      }
      if (options.progress != nullptr && found > 0)
        options.progress->step(found * std::max<std::uint64_t>(1, options.unit_weight));
      std::vector<std::uint64_t> pending;
      for (std::size_t u = 0; u < count; ++u) {
        if (!have[u]) pending.push_back(u);
      }
      // Enough units per round to keep every thread busy, and at most ~32 rounds per run: each
      // round ends in a gather, and fewer rounds wait less on the slowest rank. One rank has
      // nothing to gather, and records each unit in the store as it finishes: its units go in one
      // round, since every round ends with the threads waiting for that round's slowest unit
      // (docs/scale-out.md "Rounds").
      const auto threads = static_cast<std::size_t>(
          std::max<std::size_t>(1, tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
      const std::size_t ranks = static_cast<std::size_t>(size());
      const std::size_t per_rank = (pending.size() + ranks - 1) / ranks;
      const bool one_round = ranks == 1;
      const std::size_t batch = options.batch > 0 ? options.batch
                                : one_round       ? std::max<std::size_t>(1, per_rank)
                                                  : std::max(threads, (per_rank + 31) / 32);
      put_u64(plan, batch);
      put_u64(plan, pending.size());
      for (const std::uint64_t u : pending) put_u64(plan, u);
    } catch (const std::exception& e) {
      setup.status = kFailed;
      setup.message = e.what();
    }
  }
  if (const Decision d = broadcast(setup); d.status != kOk) throw UnitFailure(d.message, d.status == kInternal);
  broadcast(plan);
  Reader plan_reader{plan};
  const std::size_t batch = plan_reader.u64();
  std::vector<std::uint64_t> pending(plan_reader.u64());
  for (auto& u : pending) u = plan_reader.u64();

  const auto ranks = static_cast<std::size_t>(size());
  const auto me = static_cast<std::size_t>(rank());
  const std::size_t per_rank = (pending.size() + ranks - 1) / ranks;
  const std::size_t rounds = (per_rank + batch - 1) / batch;
  // One rank records a unit the moment it finishes (from the thread that ran it), so a run
  // killed inside its one round keeps every unit done so far; ranks record after each gather.
  const bool record_at_once = ranks == 1 && options.store != nullptr;
  std::atomic<std::size_t> recorded{0};
  const auto record = [&](std::uint64_t u, const Bytes& bytes) {
    options.store->save(u, bytes);
    if (kill_after && recorded.fetch_add(1) + 1 >= *kill_after) std::raise(SIGKILL);
  };
  for (std::size_t round = 0; round < rounds; ++round) {
    // This rank's units of the round: its slots round·batch … of the cyclic assignment.
    std::vector<std::uint64_t> mine;
    for (std::size_t i = round * batch; i < std::min(per_rank, (round + 1) * batch); ++i) {
      const std::size_t slot = i * ranks + me;
      if (slot < pending.size()) mine.push_back(pending[slot]);
    }
    std::vector<Bytes> out(mine.size());
    std::vector<char> ok(mine.size(), 0);
    std::vector<double> unit_seconds(mine.size(), 0.0);
    std::vector<double> unit_cpu(mine.size(), 0.0);
    std::mutex failure_mutex;
    std::optional<std::size_t> failed;  // index into `mine` of the lowest failing unit
    std::string failed_what;
    bool failed_internal = false;
    // A Cancelled (Ctrl-C, a failing callback: core/progress.h) stops the round: the units not
    // begun are skipped, and one process hands the Cancelled to its caller unchanged.
    std::atomic<bool> cancelled{false};
    parallel_units(mine.size(), [&](std::size_t k) {
      if (cancelled.load(std::memory_order_relaxed)) return;
      const std::size_t u = mine[k];
      std::string what;
      bool internal = false;
      try {
        if (fail_unit && *fail_unit == u) throw Error("failed on purpose (test hook WEFT_TEST_FAIL_UNIT)");
        const auto t0 = std::chrono::steady_clock::now();
        const double cpu0 = thread_cpu_seconds();
        out[k] = body(u);
        unit_cpu[k] = thread_cpu_seconds() - cpu0;
        unit_seconds[k] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (record_at_once) record(u, out[k]);
        ok[k] = 1;
        if (root && options.progress != nullptr && options.unit_weight == 0) options.progress->step();
        return;
      } catch (const Cancelled& e) {
        cancelled.store(true, std::memory_order_relaxed);
        what = e.what();
      } catch (const Error& e) {
        what = e.what();
      } catch (const std::exception& e) {
        what = e.what();
        internal = true;
      } catch (...) {
        what = "unknown exception";
        internal = true;
      }
      const std::lock_guard lock(failure_mutex);
      if (!failed || k < *failed) {
        failed = k;
        failed_what = what;
        failed_internal = internal;
      }
    });
    if (cancelled.load() && ranks == 1) throw Cancelled();
    Bytes message;
    if (failed) {
      put_u64(message, failed_internal ? kInternal : kFailed);
      put_u64(message, mine[*failed]);
      put_bytes(message, reinterpret_cast<const std::uint8_t*>(failed_what.data()), failed_what.size());
    } else {
      put_u64(message, kOk);
      put_u64(message, 0);
      put_bytes(message, nullptr, 0);
    }
    // The units that finished (rank 0 keeps its own results where they are).
    put_u64(message, root ? 0 : static_cast<std::uint64_t>(std::count(ok.begin(), ok.end(), 1)));
    if (!root) {
      for (std::size_t k = 0; k < mine.size(); ++k) {
        if (ok[k] == 0) continue;
        put_u64(message, mine[k]);
        put_u64(message, std::bit_cast<std::uint64_t>(unit_seconds[k]));
        put_u64(message, std::bit_cast<std::uint64_t>(unit_cpu[k]));
        put_bytes(message, out[k].data(), out[k].size());
      }
    }
    const auto t_gather = std::chrono::steady_clock::now();
    const double cpu_gather = thread_cpu_seconds();
    const std::vector<Bytes> all = gather_to_root(message);

    Decision decision;
    if (root) {
      try {
        std::vector<std::uint64_t> finished;
        for (std::size_t k = 0; k < mine.size(); ++k) {
          if (ok[k] == 0) continue;
          if (costs) costs->unit(mine[k], 0, unit_seconds[k], out[k].size(), unit_cpu[k]);
          results[mine[k]] = std::move(out[k]);
          finished.push_back(mine[k]);
        }
        std::optional<std::pair<std::uint64_t, std::size_t>> first;  // (unit, rank) of the lowest failure
        std::string first_what;
        std::uint64_t first_status = kOk;
        for (std::size_t r = 0; r < all.size(); ++r) {
          Reader in{all[r]};
          const std::uint64_t status = in.u64();
          const std::uint64_t unit = in.u64();
          const Bytes what = in.bytes();
          if (status != kOk && (!first || unit < first->first)) {
            first = std::make_pair(unit, r);
            first_what.assign(what.begin(), what.end());
            first_status = status;
          }
          const std::uint64_t n = in.u64();
          for (std::uint64_t k = 0; k < n; ++k) {
            const std::uint64_t u = in.u64();
            if (u >= count) throw Error(fmt::format("distributed run: rank {} sent unit {} of {}", r, u, count));
            const double seconds = std::bit_cast<double>(in.u64());
            const double cpu = std::bit_cast<double>(in.u64());
            results[u] = in.bytes();
            if (costs) costs->unit(u, r, seconds, results[u].size(), cpu);
            finished.push_back(u);
          }
          if (r > 0 && options.progress != nullptr)
            options.progress->step(n * std::max<std::uint64_t>(1, options.unit_weight));
        }
        // Units finished this round are recorded even when another one failed: a rerun with
        // --resume then only redoes what is missing.
        if (options.store != nullptr && !record_at_once) {
          std::sort(finished.begin(), finished.end());
          for (const std::uint64_t u : finished) record(u, results[u]);
        }
        if (first) {
          decision.status = first_status;
          decision.message =
              ranks > 1 ? fmt::format("{} failed on rank {}: {}", name(first->first), first->second, first_what)
                        : fmt::format("{} failed: {}", name(first->first), first_what);
        }
      } catch (const std::exception& e) {
        decision.status = kFailed;
        decision.message = e.what();
      }
    }
    const Decision d = broadcast(decision);
    if (costs) {
      std::size_t bytes = 0;
      for (const auto& m : all) bytes += m.size();
      costs->round(round, std::chrono::duration<double>(std::chrono::steady_clock::now() - t_gather).count(), bytes,
                   thread_cpu_seconds() - cpu_gather);
    }
    if (d.status != kOk) throw UnitFailure(d.message, d.status == kInternal);
  }
  return results;
}

}  // namespace weft::dist
