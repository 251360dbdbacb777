#include "weft/core/progress.h"

#include <algorithm>
#include <utility>

namespace weft {
namespace {
class NullProgress final : public ProgressSink {
 public:
  void begin(std::string_view /*label*/, std::uint64_t /*total*/) override {}
  void advance(std::uint64_t /*done_so_far*/) override {}
  void end() noexcept override {}
};

std::atomic<const std::atomic<int>*> g_stop_request{nullptr};
}  // namespace

void set_stop_request(const std::atomic<int>* flag) noexcept { g_stop_request.store(flag); }

void stop_if_requested() {
  const std::atomic<int>* flag = g_stop_request.load();
  if (flag != nullptr && flag->load(std::memory_order_relaxed) != 0) throw Cancelled();
}

ProgressSink& null_progress() {
  static NullProgress sink;
  return sink;
}

ProgressTask::ProgressTask(ProgressSink& sink, std::string_view label, std::uint64_t total) : sink_(sink) {
  sink_.begin(label, total);
}

ProgressTask::ProgressTask(ProgressSink& sink, std::string_view label, std::uint64_t total, std::string_view unit)
    : sink_(sink) {
  sink_.begin_counting(label, total, unit);
}

// end() is noexcept (ProgressSink's contract), so closing a stage while a Cancelled unwinds
// cannot terminate the process.
ProgressTask::~ProgressTask() { sink_.end(); }

void ProgressTask::step(std::uint64_t units) { sink_.advance(done_.fetch_add(units) + units); }

ProgressShare::ProgressShare(ProgressTask& outer, std::uint64_t weight, std::string only)
    : outer_(outer), weight_(weight), only_(std::move(only)) {}

void ProgressShare::begin(std::string_view label, std::uint64_t total) {
  if (!only_.empty() && label != only_) {
    counting_ = false;
    reach(0);
    return;
  }
  const std::uint64_t before = stages_.fetch_add(1);
  total_ = total;
  counting_ = true;
  reach(before * weight_);  // the stages before this one, whole
}

void ProgressShare::advance(std::uint64_t done_so_far) {
  if (!counting_.load(std::memory_order_relaxed)) {
    reach(0);
    return;
  }
  const std::uint64_t total = total_.load(std::memory_order_relaxed);
  const double fraction =
      total > 0 ? static_cast<double>(std::min(done_so_far, total)) / static_cast<double>(total) : 1.0;
  const std::uint64_t stages = stages_.load(std::memory_order_relaxed);
  reach((stages > 0 ? stages - 1 : 0) * weight_ + static_cast<std::uint64_t>(fraction * static_cast<double>(weight_)));
}

void ProgressShare::finish() { reach(stages_.load() * weight_); }

void ProgressShare::reach(std::uint64_t target) {
  std::uint64_t now = counted_.load(std::memory_order_relaxed);
  while (target > now) {
    if (counted_.compare_exchange_weak(now, target)) {
      outer_.step(target - now);
      return;
    }
  }
  outer_.step(0);
}

}  // namespace weft
