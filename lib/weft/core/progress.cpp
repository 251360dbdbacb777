#include "weft/core/progress.h"

namespace weft {
namespace {
class NullProgress final : public ProgressSink {
 public:
  void begin(std::string_view /*label*/, std::uint64_t /*total*/) override {}
  void advance(std::uint64_t /*done_so_far*/) override {}
  void end() noexcept override {}
};
}  // namespace

ProgressSink& null_progress() {
  static NullProgress sink;
  return sink;
}

ProgressTask::ProgressTask(ProgressSink& sink, std::string_view label, std::uint64_t total) : sink_(sink) {
  sink_.begin(label, total);
}

// end() is noexcept (ProgressSink's contract), so closing a stage while a Cancelled unwinds
// cannot terminate the process.
ProgressTask::~ProgressTask() { sink_.end(); }

void ProgressTask::step(std::uint64_t units) { sink_.advance(done_.fetch_add(units) + units); }

}  // namespace weft
