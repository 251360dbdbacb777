// The corpus study as work units (docs/scale-out.md): study::run_corpus gives, in case order, exactly
// what run_corpus_case gives case by case — for any thread count (cases side by side or one
// after the other) and after a resume from the unit store (results read back from MessagePack),
// which is what makes the corpus's outputs the same bytes on any number of MPI ranks.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <filesystem>
#include <set>

#include "weft/core/parallel.h"
#include "weft/dist/unit_store.h"
#include "weft/study/corpus.h"

namespace weft::study {
namespace {

namespace fs = std::filesystem;

// Bitwise: NaN ratios (an exact exponential) must come back as the same NaN, and every other
// double with every digit.
void expect_same_bits(double a, double b, const std::string& what) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b)) << what << ": " << a << " vs " << b;
}

void expect_same(const CorpusResult& a, const CorpusResult& b) {
  const std::string c = a.c.name();
  EXPECT_EQ(c, b.c.name());
  expect_same_bits(a.sigma, b.sigma, c + " sigma");
  EXPECT_EQ(a.active_voxels, b.active_voxels) << c;
  ASSERT_EQ(a.axes.size(), b.axes.size()) << c;
  for (std::size_t i = 0; i < a.axes.size(); ++i) {
    const auto& x = a.axes[i];
    const auto& y = b.axes[i];
    const std::string where = c + " " + x.axis;
    EXPECT_EQ(x.axis, y.axis) << c;
    expect_same_bits(x.scale, y.scale, where + " scale");
    EXPECT_EQ(x.best.name, y.best.name) << where;
    expect_same_bits(x.best.ratio, y.best.ratio, where + " best ratio");
    ASSERT_EQ(x.models.size(), y.models.size()) << where;
    for (std::size_t m = 0; m < x.models.size(); ++m) {
      EXPECT_EQ(x.models[m].name, y.models[m].name) << where;
      expect_same_bits(x.models[m].rms_abs_t, y.models[m].rms_abs_t, where + " " + x.models[m].name + " rms");
      expect_same_bits(x.models[m].ratio, y.models[m].ratio, where + " " + x.models[m].name + " ratio");
      EXPECT_EQ(x.models[m].uses_ground_truth, y.models[m].uses_ground_truth) << where;
    }
  }
}

TEST(Corpus, CasesAreDistinctAndTheQuickCorpusIsTheirSubset) {
  const auto all = corpus_cases(false);
  const auto quick = corpus_cases(true);
  EXPECT_EQ(all.size(), 42U);  // 7 patterns x 3 presets x 2 voxel sizes
  std::set<std::string> names;
  for (const auto& c : all) names.insert(c.name());
  EXPECT_EQ(names.size(), all.size());
  ASSERT_EQ(quick.size(), 2U);
  for (const auto& c : quick) EXPECT_TRUE(names.count(c.name()) == 1) << c.name();
}

TEST(Corpus, SelectKeepsTheCasesNamingAPartInCorpusOrder) {
  const auto all = corpus_cases(false);
  EXPECT_EQ(select_corpus_cases(all, {}).size(), all.size());
  const auto fine = select_corpus_cases(all, {"20um"});
  EXPECT_EQ(fine.size(), 21U);
  for (const auto& c : fine) EXPECT_DOUBLE_EQ(c.voxel_size, 0.02) << c.name();
  const auto two = select_corpus_cases(all, {"satin5-wool-10um", "plain-cotton-20um"});
  ASSERT_EQ(two.size(), 2U);
  EXPECT_EQ(two[0].name(), "plain-cotton-20um");  // corpus order, not the order asked
  EXPECT_EQ(two[1].name(), "satin5-wool-10um");
  EXPECT_THROW((void)select_corpus_cases(all, {"plain", "satin9"}), Error);
  EXPECT_THROW((void)select_corpus_cases(all, {""}), Error);
}

TEST(Corpus, UnitsGiveEveryCaseAloneForAnyThreadsAndAfterAResume) {
  const auto cases = corpus_cases(true);
  const std::uint64_t seed = 3;
  std::vector<CorpusResult> alone;
  for (const auto& c : cases) alone.push_back(run_corpus_case(c, seed, "yarn"));
  for (const unsigned threads : {1U, 2U}) {
    const ThreadLimit limit(threads);
    const auto units = run_corpus(cases, seed, "yarn");
    ASSERT_EQ(units.size(), cases.size());
    for (std::size_t i = 0; i < cases.size(); ++i) expect_same(alone[i], units[i]);
  }

  // Record every case, forget the last one, resume: case 0 comes from disk, case 1 is recomputed.
  const fs::path dir = fs::temp_directory_path() / "weft_corpus_test_units";
  fs::remove_all(dir);
  {
    dist::UnitStore store(dir, "corpus test", false);
    (void)run_corpus(cases, seed, "yarn", null_progress(), &store);
  }
  ASSERT_TRUE(fs::exists(dir / "unit-000000.bin"));
  ASSERT_TRUE(fs::remove(dir / "unit-000001.bin"));
  dist::UnitStore store(dir, "corpus test", true);
  const auto resumed = run_corpus(cases, seed, "yarn", null_progress(), &store);
  EXPECT_EQ(store.found(), 1U);
  ASSERT_EQ(resumed.size(), cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) expect_same(alone[i], resumed[i]);
  store.remove();
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Corpus, NoCasesIsRefused) { EXPECT_THROW((void)run_corpus({}, 1, "yarn"), Error); }

}  // namespace
}  // namespace weft::study
