#include "weft/core/progress.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>

#include "weft/core/parallel.h"

namespace {

// A sink that asks to stop at its `stop_at`-th advance and counts what it saw.
struct StoppingSink : weft::ProgressSink {
  explicit StoppingSink(std::uint64_t stop_at) : stop_at(stop_at) {}
  void begin(std::string_view /*label*/, std::uint64_t /*total*/) override { ++begins; }
  void advance(std::uint64_t /*done*/) override {
    if (++advances >= stop_at) throw weft::Cancelled();
  }
  void end() noexcept override { ++ends; }
  std::uint64_t stop_at;
  std::atomic<int> begins{0};
  std::atomic<std::uint64_t> advances{0};
  std::atomic<int> ends{0};
};

// docs/python.md "Interrupting a call": Cancelled thrown from a step inside the parallel loop
// reaches the caller, the stage is closed once, and the loop does not run to its end.
TEST(Progress, CancelledFromAParallelStepReachesTheCallerAndClosesTheStage) {
  constexpr std::size_t kUnits = 100000;
  StoppingSink sink(10);
  std::atomic<std::size_t> ran{0};
  EXPECT_THROW(
      {
        weft::ProgressTask task(sink, "work", kUnits);
        weft::parallel_units(kUnits, [&](std::size_t) {
          ++ran;
          task.step();
        });
      },
      weft::Cancelled);
  EXPECT_EQ(sink.begins, 1);
  EXPECT_EQ(sink.ends, 1);
  EXPECT_LT(ran.load(), kUnits);
}

TEST(Progress, ASinkThatNeverStopsSeesEveryStep) {
  StoppingSink sink(~std::uint64_t{0});
  {
    weft::ProgressTask task(sink, "work", 1000);
    weft::parallel_units(1000, [&](std::size_t) { task.step(); });
  }
  EXPECT_EQ(sink.advances.load(), 1000U);
  EXPECT_EQ(sink.ends, 1);
}

}  // namespace
