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

// A sink that records the last count of its one stage.
struct CountingSink : weft::ProgressSink {
  void begin(std::string_view /*label*/, std::uint64_t t) override { total = t; }
  void advance(std::uint64_t done) override {
    if (done > last) last = done;
    ++advances;
  }
  void end() noexcept override {}
  std::uint64_t total = 0;
  std::uint64_t last = 0;
  int advances = 0;
};

// docs/render.md §6e: an inner computation's stages move the outer stage by their share as
// they go; a stage of another label counts nothing but still reports (so a stop reaches it).
TEST(Progress, AShareMovesTheOuterStageByItsStagesFractions) {
  CountingSink outer;
  weft::ProgressTask task(outer, "outer", 3000);
  weft::ProgressShare share(task, 1000, "counted");
  share.begin("preparation", 50);
  share.advance(50);
  EXPECT_EQ(outer.last, 0U);
  EXPECT_EQ(outer.advances, 2);  // reported, counting nothing
  share.begin("counted", 8);
  share.advance(2);
  EXPECT_EQ(outer.last, 250U);
  share.advance(1);  // late and out of order: never back
  EXPECT_EQ(outer.last, 250U);
  share.end();
  share.begin("counted", 4);  // the first stage's rest, then this one's share
  EXPECT_EQ(outer.last, 1000U);
  share.advance(3);
  EXPECT_EQ(outer.last, 1750U);
  share.finish();
  EXPECT_EQ(outer.last, 2000U);
}

TEST(Progress, AStopOfTheOuterSinkReachesTheInnerComputation) {
  StoppingSink outer(3);
  weft::ProgressTask task(outer, "outer", 1000);
  weft::ProgressShare share(task, 1000);
  EXPECT_THROW(
      {
        weft::ProgressTask inner(share, "inner", 100000);
        weft::parallel_units(100000, [&](std::size_t) { inner.step(); });
      },
      weft::Cancelled);
  EXPECT_LT(outer.advances.load(), 100000U);
}
