#pragma once
/// @file
/// @brief Sharded parallel loops whose results do not depend on the thread count.

#include <cstddef>
#include <functional>
#include <memory>

namespace weft {

/// @brief Runs `body(unit)` for unit in [0, count) over the TBB pool.
///
/// Callers make each unit's work depend only on its index (its RNG stream comes from
/// stream_for(seed, unit)) and reduce unit results in index order afterwards, which is what
/// makes outputs identical for any thread count (docs/architecture.md §5).
void parallel_units(std::size_t count, const std::function<void(std::size_t unit)>& body);

/// Most worker threads a run may ask for (the CLI's --threads, Python's threads=): far above any
/// machine weft runs on, low enough that a typo (a count of rays as threads) is refused.
inline constexpr unsigned kMaxThreads = 1024;

/// @brief Limits the TBB pool to `threads` worker threads while alive (0 = all cores); more than
/// kMaxThreads throws weft::Error.
class ThreadLimit {
 public:
  explicit ThreadLimit(unsigned threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// @brief Number of hardware threads TBB will use by default.
unsigned default_thread_count();

/// @brief Number of threads parallel_units may run at once now: default_thread_count() within
/// the innermost live ThreadLimit (what per-thread scratch memory is estimated for).
unsigned thread_count();

}  // namespace weft
