// dist::run_units in one process (the tests run without mpirun; the multi-rank behaviour is
// checked end to end by tests/cli/cli_mpi.cmake) and dist::UnitStore.
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/dist/distributed.h"
#include "weft/dist/unit_store.h"

namespace weft::dist {
namespace {

namespace fs = std::filesystem;

Bytes bytes_of(const std::string& s) { return Bytes(s.begin(), s.end()); }
std::string text_of(const Bytes& b) { return std::string(b.begin(), b.end()); }

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("weft_dist_test_" + name);
  fs::remove_all(d);
  return d;
}

TEST(RunUnits, OneProcessIsRankZeroOfOne) {
  EXPECT_EQ(rank(), 0);
  EXPECT_EQ(size(), 1);
  EXPECT_TRUE(is_root());
}

TEST(RunUnits, RankLocalUnitsRunNestedWorkOnTheirOwnRank) {
  // A unit that is a whole computation (a study case) runs run_units of its own inside a
  // RankLocal scope: there it is rank 0 of 1, its nested units come back in order and
  // root_decides is its own decision; outside the scopes the process is itself again.
  const ThreadLimit limit(2);
  UnitsOptions how;
  how.batch = 2;
  const auto out = run_units(
      6,
      [](std::size_t u) {
        const RankLocal local;
        EXPECT_EQ(rank(), 0);
        EXPECT_EQ(size(), 1);
        EXPECT_EQ(root_decides(u % 2 == 0), u % 2 == 0);
        const auto inner = run_units(5, [u](std::size_t v) { return bytes_of(std::to_string(u * 10 + v)); });
        std::string all;
        for (const auto& b : inner) all += text_of(b) + ",";
        return bytes_of(all);
      },
      how);
  ASSERT_EQ(out.size(), 6U);
  for (std::size_t u = 0; u < out.size(); ++u) {
    std::string want;
    for (std::size_t v = 0; v < 5; ++v) want += std::to_string(u * 10 + v) + ",";
    EXPECT_EQ(text_of(out[u]), want);
  }
  EXPECT_EQ(rank(), 0);
  EXPECT_EQ(size(), 1);
}

TEST(RunUnits, ResultsComeBackInUnitOrderForAnyThreadsAndBatch) {
  for (const unsigned threads : {1U, 2U, 4U}) {
    const ThreadLimit limit(threads);
    for (const std::size_t batch : {0U, 1U, 3U, 100U}) {
      UnitsOptions how;
      how.batch = batch;
      const auto out = run_units(
          37, [](std::size_t u) { return bytes_of("unit " + std::to_string(u * u)); }, how);
      ASSERT_EQ(out.size(), 37U);
      for (std::size_t u = 0; u < out.size(); ++u) EXPECT_EQ(text_of(out[u]), "unit " + std::to_string(u * u));
    }
  }
}

TEST(RunUnits, OneRankWithoutAStoreRunsOneRound) {
  // Every round ends with the threads waiting for its slowest unit; one rank without a store has
  // nothing to gather or record between rounds, so all its units go in one (the cost log's rows).
  const fs::path d = fresh_dir("one_round");
  fs::create_directories(d);
  const fs::path log = d / "costs.csv";
  ASSERT_EQ(setenv("WEFT_UNIT_COSTS", log.c_str(), 1), 0);
  {
    const ThreadLimit limit(2);
    (void)run_units(200, [](std::size_t u) { return Bytes{static_cast<std::uint8_t>(u)}; });
  }
  ASSERT_EQ(unsetenv("WEFT_UNIT_COSTS"), 0);
  std::ifstream in(log);
  int rounds = 0;
  int units = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.find(",round,") != std::string::npos) ++rounds;
    if (line.find(",unit,") != std::string::npos) ++units;
  }
  EXPECT_EQ(units, 200);
  EXPECT_EQ(rounds, 1);
  fs::remove_all(d);
}

TEST(RunUnits, NoUnitsIsNoWork) {
  const auto out = run_units(0, [](std::size_t) -> Bytes { throw Error("never called"); });
  EXPECT_TRUE(out.empty());
}

/// The last count a stage reached.
struct Counter : ProgressSink {
  std::atomic<std::uint64_t> last{0};
  void begin(std::string_view, std::uint64_t) override {}
  void advance(std::uint64_t done) override { last = std::max<std::uint64_t>(last, done); }
  void end() noexcept override {}
};

TEST(RunUnits, ProgressCountsEveryUnit) {
  Counter sink;
  {
    ProgressTask task(sink, "units", 20);
    UnitsOptions how;
    how.progress = &task;
    (void)run_units(
        20, [](std::size_t) { return Bytes{1}; }, how);
  }
  EXPECT_EQ(sink.last.load(), 20U);
}

// UnitsOptions::unit_weight (docs/render.md §6e): the body steps its own units as it goes, and
// run_units adds the weight of each resumed unit, never a unit's weight twice.
TEST(RunUnits, AWeightedUnitIsCountedOnceWhetherRunOrResumed) {
  const fs::path dir = fresh_dir("weighted");
  {
    UnitStore store(dir, "key W", false);
    store.open();
    for (const std::size_t u : {std::size_t{1}, std::size_t{3}}) store.save(u, bytes_of("done"));
  }
  Counter sink;
  UnitStore store(dir, "key W", true);
  {
    ProgressTask task(sink, "weighted units", 5 * 10);
    UnitsOptions how;
    how.progress = &task;
    how.unit_weight = 10;
    how.store = &store;
    (void)run_units(
        5,
        [&](std::size_t) {
          for (int i = 0; i < 10; ++i) task.step();
          return bytes_of("run");
        },
        how);
  }
  EXPECT_EQ(store.found(), 2U);
  EXPECT_EQ(sink.last.load(), 50U);
  store.remove();
}

TEST(RunUnits, AFailingUnitIsNamedAndLowestFirst) {
  UnitsOptions how;
  how.name = [](std::size_t u) { return "point " + std::to_string(u); };
  how.batch = 10;
  try {
    (void)run_units(
        10,
        [](std::size_t u) -> Bytes {
          if (u == 7 || u == 4) throw Error("bad point " + std::to_string(u));
          return {};
        },
        how);
    FAIL() << "no exception";
  } catch (const UnitFailure& e) {
    EXPECT_STREQ(e.what(), "point 4 failed: bad point 4");
    EXPECT_FALSE(e.internal());
  }
}

TEST(RunUnits, AStandardExceptionIsAnInternalFailure) {
  try {
    (void)run_units(3, [](std::size_t u) -> Bytes {
      if (u == 2) throw std::runtime_error("boom");
      return {};
    });
    FAIL() << "no exception";
  } catch (const UnitFailure& e) {
    EXPECT_STREQ(e.what(), "unit 2 failed: boom");
    EXPECT_TRUE(e.internal());
  }
}

TEST(RunUnits, CancelledPassesUnchangedAndStopsTheRound) {
  // A Cancelled (core/progress.h: Ctrl-C from Python, a failing callback) is not a unit failure:
  // it reaches the caller as itself, and the units not begun are skipped instead of run to the
  // end of the one round a single process has (docs/architecture.md §5).
  for (const unsigned threads : {1U, 2U}) {
    const ThreadLimit limit(threads);
    std::atomic<int> ran{0};
    constexpr std::size_t kUnits = 10000;
    EXPECT_THROW((void)run_units(kUnits,
                                 [&](std::size_t u) -> Bytes {
                                   ran.fetch_add(1);
                                   if (u == 3) throw Cancelled();
                                   return {};
                                 }),
                 Cancelled);
    // Without the skip every unit would run; with it, at most the units already begun by the
    // other threads (TBB hands out ranges, so allow a generous share, far below kUnits).
    EXPECT_LT(ran.load(), static_cast<int>(kUnits / 2)) << threads << " threads";
  }
}

TEST(UnitStore, ResumeSkipsRecordedUnitsAndGivesTheSameResults) {
  const fs::path dir = fresh_dir("resume");
  const auto body = [](std::size_t u) { return bytes_of(std::to_string(3 * u + 1)); };
  std::atomic<int> calls{0};
  {
    UnitStore store(dir, "key A", false);
    UnitsOptions how;
    how.store = &store;
    how.batch = 1;
    // The run dies at unit 5 (after units 0..4 were recorded, one per round).
    EXPECT_THROW((void)run_units(
                     8,
                     [&](std::size_t u) {
                       if (u == 5) throw Error("died");
                       return body(u);
                     },
                     how),
                 UnitFailure);
  }
  for (std::size_t u = 0; u < 5; ++u) EXPECT_TRUE(fs::exists(dir / ("unit-00000" + std::to_string(u) + ".bin")));
  EXPECT_FALSE(fs::exists(dir / "unit-000005.bin"));
  UnitStore store(dir, "key A", true);
  UnitsOptions how;
  how.store = &store;
  const auto out = run_units(
      8,
      [&](std::size_t u) {
        ++calls;
        return body(u);
      },
      how);
  EXPECT_EQ(store.found(), 5U);
  EXPECT_EQ(calls.load(), 3);
  for (std::size_t u = 0; u < 8; ++u) EXPECT_EQ(out[u], body(u));
  store.remove();
  EXPECT_FALSE(fs::exists(dir));
}

TEST(UnitStore, ResumeRefusesAnotherRunsUnits) {
  const fs::path dir = fresh_dir("other");
  {
    UnitStore store(dir, "key A", false);
    UnitsOptions how;
    how.store = &store;
    (void)run_units(
        2, [](std::size_t) { return Bytes{7}; }, how);
  }
  UnitStore other(dir, "key B", true);
  UnitsOptions how;
  how.store = &other;
  EXPECT_THAT(
      [&] {
        (void)run_units(
            2, [](std::size_t) { return Bytes{7}; }, how);
      },
      ::testing::ThrowsMessage<UnitFailure>(::testing::HasSubstr("different run")));
  // A fresh (not resumed) run with another key starts over instead.
  UnitStore fresh(dir, "key B", false);
  how.store = &fresh;
  std::atomic<int> calls{0};
  (void)run_units(
      2,
      [&](std::size_t) {
        ++calls;
        return Bytes{8};
      },
      how);
  EXPECT_EQ(calls.load(), 2);
  fs::remove_all(dir);
}

TEST(RootBytes, RankZerosBytesComeBackWhole) {
  // One process is rank 0: its bytes, every one of them, including zeros and an empty value
  // (under mpirun the matrix's albedo factors take this path: cli.mpi.same_bytes.render_matrix).
  const Bytes value{0, 1, 2, 255, 0, 7};
  EXPECT_EQ(root_bytes(value), value);
  EXPECT_TRUE(root_bytes({}).empty());
}

}  // namespace
}  // namespace weft::dist
