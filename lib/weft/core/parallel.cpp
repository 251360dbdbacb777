#include "weft/core/parallel.h"

#include <algorithm>

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "weft/core/error.h"

namespace weft {

void parallel_units(std::size_t count, const std::function<void(std::size_t)>& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
  });
}

struct ThreadLimit::Impl {
  std::unique_ptr<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(unsigned threads) : impl_(std::make_unique<Impl>()) {
  if (threads > kMaxThreads) fail("threads must be in [0, {}] (0 = every core), got {}", kMaxThreads, threads);
  if (threads > 0) {
    impl_->control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  }
}

ThreadLimit::~ThreadLimit() = default;

unsigned default_thread_count() { return static_cast<unsigned>(tbb::info::default_concurrency()); }

unsigned thread_count() {
  const std::size_t allowed = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  return static_cast<unsigned>(std::min<std::size_t>(allowed, default_thread_count()));
}

}  // namespace weft
