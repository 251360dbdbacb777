#pragma once
// A progress sink for the unit tests that check how a computation reports and stops: it counts the
// reports and throws Cancelled at a given one, as the app's sink does after a Ctrl-C.
#include <atomic>
#include <cstdint>
#include <string_view>

#include "weft/core/progress.h"

namespace weft::test {

/// Counts reports; throws Cancelled at report `stop_at` (0: never).
class CountingSink final : public ProgressSink {
 public:
  explicit CountingSink(std::uint64_t stop_at = 0) : stop_at_(stop_at) {}
  void begin(std::string_view /*label*/, std::uint64_t /*total*/) override {}
  void advance(std::uint64_t /*done_so_far*/) override {
    if (++reports_ == stop_at_) throw Cancelled();
  }
  void end() noexcept override {}
  [[nodiscard]] std::uint64_t reports() const { return reports_.load(); }

 private:
  std::uint64_t stop_at_;
  std::atomic<std::uint64_t> reports_{0};
};

}  // namespace weft::test
