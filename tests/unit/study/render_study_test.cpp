// The study's bias estimator (bias_estimate.h: estimate_bias) on synthetic images whose truth is known:
// a, b = truth + shift + noise (σ_c), reference = truth + noise (σ_r) carrying its variance; and
// what check_study_spec refuses.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/study/bias_estimate.h"
#include "weft/study/render_study.h"
#include "weft/study/render_study_report.h"
#include "weft/transmittance/gamma_hazard.h"

namespace weft::study {
using namespace weft::render;  // NOLINT(google-build-using-namespace)
namespace {

struct Triple {
  Image a;
  Image b;
  Image reference;
};

Triple synthetic(double shift, double sigma_candidate, double sigma_reference, std::uint64_t seed) {
  constexpr int kW = 100;
  constexpr int kH = 100;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> truth(0.0, 1.0);
  std::normal_distribution<double> unit(0.0, 1.0);
  Triple t;
  for (Image* im : {&t.a, &t.b, &t.reference}) {
    im->width = kW;
    im->height = kH;
    im->rgb.resize(static_cast<std::size_t>(kW) * kH * 3);
  }
  t.reference.variance.assign(t.reference.rgb.size(), static_cast<float>(sigma_reference * sigma_reference));
  for (std::size_t i = 0; i < t.reference.rgb.size(); ++i) {
    const double v = truth(rng);
    t.a.rgb[i] = static_cast<float>(v + shift + sigma_candidate * unit(rng));
    t.b.rgb[i] = static_cast<float>(v + shift + sigma_candidate * unit(rng));
    t.reference.rgb[i] = static_cast<float>(v + sigma_reference * unit(rng));
  }
  return t;
}

TEST(StudyBias, UnbiasedCandidateIsZeroWithinFiveStandardErrors) {
  // Noise much larger than any bias could hide: the estimate must still centre on 0.
  for (std::uint64_t seed : {1U, 2U, 3U}) {
    const Triple t = synthetic(0.0, 0.2, 0.03, seed);
    const BiasEstimate e = estimate_bias(t.a, t.b, t.reference);
    EXPECT_GT(e.stderr_sq, 0.0);
    EXPECT_LT(std::abs(e.bias_sq), 5.0 * e.stderr_sq) << "seed " << seed;
  }
}

TEST(StudyBias, ShiftedCandidateGivesTheShiftSquared) {
  // A constant shift d is a bias of d in every value: bias² = d² within 5 standard errors,
  // and far from 0 (the estimator sees it through noise of 4× the shift).
  const double d = 0.05;
  const Triple t = synthetic(d, 0.2, 0.03, 7);
  const BiasEstimate e = estimate_bias(t.a, t.b, t.reference);
  EXPECT_LT(std::abs(e.bias_sq - d * d), 5.0 * e.stderr_sq);
  EXPECT_GT(e.bias_sq, 5.0 * e.stderr_sq);
}

TEST(StudyBias, IgnoringTheReferenceVarianceWouldBiasTheEstimate) {
  // Without the var r term the estimate would be off by σ_r²; the estimator subtracts it.
  const double sigma_r = 0.1;
  Triple t = synthetic(0.0, 0.05, sigma_r, 11);
  const BiasEstimate with = estimate_bias(t.a, t.b, t.reference);
  t.reference.variance.clear();
  const BiasEstimate without = estimate_bias(t.a, t.b, t.reference);
  EXPECT_LT(std::abs(with.bias_sq), 5.0 * with.stderr_sq);
  EXPECT_LT(std::abs(without.bias_sq - sigma_r * sigma_r), 5.0 * without.stderr_sq);
}

TEST(StudyBias, ImagesOfDifferentSizesAreRefused) {
  Triple t = synthetic(0.0, 0.1, 0.1, 1);
  t.b.width = 50;
  EXPECT_THROW((void)estimate_bias(t.a, t.b, t.reference), Error);
}

TEST(StudySpec, BadFieldsAreNamed) {
  StudySpec s;
  s.work_dir = "x";
  EXPECT_NO_THROW(check_study_spec(s));
  s.factors = {2, 2};
  EXPECT_THROW(check_study_spec(s), Error);
  s.factors = {1};
  EXPECT_THROW(check_study_spec(s), Error);
  s.factors = {2};
  s.seconds = std::nan("");
  EXPECT_THROW(check_study_spec(s), Error);
  s.spp = 4;  // a fixed spp needs no budget
  EXPECT_NO_THROW(check_study_spec(s));
  s.reference_spp = 0;
  EXPECT_THROW(check_study_spec(s), Error);
}

// A memory rule given twice would render its candidates twice under one name (docs/robustness.md
// "Options that would do nothing").
TEST(StudySpec, AMemoryRuleGivenTwiceIsRefused) {
  using transmittance::MemoryRule;
  StudySpec s;
  s.work_dir = "x";
  s.memory_rules = {MemoryRule::segment, transmittance::kDefaultMemoryRule};
  EXPECT_NO_THROW(check_study_spec(s));
  s.memory_rules.push_back(MemoryRule::segment);
  EXPECT_THAT([&] { check_study_spec(s); },
              testing::ThrowsMessage<Error>(testing::HasSubstr("memory rule 'segment' is given twice")));
}

// Every family of candidates can be split into its components (docs/render.md §6e): a family is
// a candidate's name without "-Nx", shadow-directional included.
TEST(StudySpec, EveryCandidateFamilyCanBeSplit) {
  StudySpec s;
  s.work_dir = "x";
  s.memory_rules = {transmittance::kDefaultMemoryRule, transmittance::MemoryRule::segment};
  const std::vector<std::string> families = candidate_families(s);
  EXPECT_NE(std::find(families.begin(), families.end(), "shadow-directional"), families.end());
  for (const std::string& f : families) {
    s.components = {f};
    EXPECT_NO_THROW(check_study_spec(s)) << f;
  }
  s.components = {"expo"};
  EXPECT_THAT([&] { check_study_spec(s); },
              testing::ThrowsMessage<Error>(testing::HasSubstr("'expo': no such candidate family")));
}

// local-gamma-RULE of a rule the study does not render is named as such, with the option that
// adds the rule spelt for the caller (docs/python.md "One set of checks").
TEST(StudySpec, ALocalGammaRuleNotRenderedNamesTheOptionThatAddsIt) {
  using testing::HasSubstr;
  using testing::Not;
  using testing::ThrowsMessage;
  StudySpec s;
  s.work_dir = "x";
  s.memory_rules = {transmittance::kDefaultMemoryRule, transmittance::MemoryRule::segment};
  s.components = {"exponential", "local-gamma-renewal"};
  EXPECT_THAT([&] { check_study_spec(s, FrontEnd::cli); },
              ThrowsMessage<Error>(HasSubstr("'local-gamma-renewal': renewal is not one of the study's memory rules "
                                             "(optical-depth, segment); add it to --study-memory")));
  EXPECT_THAT([&] { check_study_spec(s, FrontEnd::python); },
              ThrowsMessage<Error>(testing::AllOf(HasSubstr("add it to memory="), Not(HasSubstr("--")))));
  s.memory_rules = {transmittance::MemoryRule::segment};  // no local-gamma-Nx candidates then
  s.components = {"local-gamma"};
  EXPECT_THAT([&] { check_study_spec(s); },
              ThrowsMessage<Error>(HasSubstr("optical-depth is not one of the study's memory rules (segment)")));
  s.memory_rules = {transmittance::kDefaultMemoryRule};
  s.components = {"local-gamma-optical-depth"};
  EXPECT_THAT([&] { check_study_spec(s); }, ThrowsMessage<Error>(HasSubstr("give 'local-gamma'")));
}

}  // namespace
}  // namespace weft::study

// The headline names the best prediction: a candidate fitted to images (with --study-albedo fit,
// to this very reference) is reported but never crowned, and a note says why, however fast it is.
TEST(StudyHeadline, ACandidateFittedToImagesIsNeverTheHeadline) {
  weft::study::StudyResult r;
  r.reference_mean = 1.0;
  const auto candidate = [](const char* name, int factor, double seconds, double rmse, bool fitted) {
    weft::study::StudyCandidate c;
    c.name = name;
    c.model = name;
    c.factor = factor;
    c.spp = 8;
    c.seconds = seconds;
    c.rmse = rmse;
    c.fitted_to_images = fitted;
    return c;
  };
  r.candidates = {candidate("fine", 1, 1.0, 0.1, false), candidate("exponential-4x", 4, 0.5, 0.1, false),
                  candidate("albedo-corrected-4x", 4, 0.25, 0.1, true)};
  weft::study::judge_study(r);
  EXPECT_DOUBLE_EQ(r.candidates[2].speedup, 4.0);  // its figures stay reported
  EXPECT_THAT(r.headline, ::testing::HasSubstr("exponential-4x"));
  EXPECT_THAT(r.headline, ::testing::Not(::testing::HasSubstr("albedo-corrected")));
  ASSERT_EQ(r.notes.size(), 1U);
  EXPECT_THAT(r.notes[0], ::testing::HasSubstr("uses_ground_truth"));
  // Without a fitted candidate, no note.
  r.candidates.pop_back();
  r.notes.clear();
  weft::study::judge_study(r);
  EXPECT_TRUE(r.notes.empty());
  EXPECT_THAT(r.headline, ::testing::HasSubstr("exponential-4x"));
}
