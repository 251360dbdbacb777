// The study matrix (render_matrix.h, render_matrix_report.h): the equal-error speed-up against its
// formula, and every representation's memory against the grids' own counts on a tiny run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/core/progress.h"
#include "weft/dist/unit_store.h"
#include "weft/fit/local_fields.h"
#include "weft/study/render_matrix.h"
#include "weft/study/render_matrix_report.h"
#include "weft/study/render_study_report.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::study {
namespace {

namespace fs = std::filesystem;

StudyCandidate candidate(int factor, double bias, double noise, int spp, double cpu) {
  StudyCandidate c;
  c.factor = factor;
  c.cloth_bias = bias;
  c.cloth_noise = noise;
  c.spp = spp;
  c.cpu_seconds = cpu;
  return c;
}

TEST(MatrixSpeedup, FollowsTheEqualErrorFormula) {
  const double mean = 2.0;  // E = 0.1
  const StudyCandidate fine = candidate(1, 0.003, 0.2, 16, 8.0);
  EXPECT_EQ(equal_error_speedup(fine, fine, mean), 1.0);
  // Same noise per sample, half the cost per sample, no bias: twice as fast.
  EXPECT_NEAR(equal_error_speedup(candidate(4, 0.0, 0.2, 16, 4.0), fine, mean), 2.0, 1e-12);
  // The same noise per sample from 4x the samples (noise halves), same cost per sample: 1.
  EXPECT_NEAR(equal_error_speedup(candidate(4, 0.0, 0.1, 64, 32.0), fine, mean), 1.0, 1e-12);
  // A bias b leaves E² − b² of the error budget to the noise.
  EXPECT_NEAR(equal_error_speedup(candidate(4, 0.06, 0.2, 16, 8.0), fine, mean), 1.0 - 0.36, 1e-12);
  // A bias at or above E never reaches it.
  EXPECT_EQ(equal_error_speedup(candidate(4, 0.1, 0.2, 16, 1.0), fine, mean), 0.0);
  EXPECT_EQ(equal_error_speedup(candidate(4, 0.3, 0.2, 16, 1.0), fine, mean), 0.0);
}

// The speed-up at RMSE E is r (1 − b²/E²): its ceiling r bounds it at every E, and the error at
// which it reaches a target is where that formula says, checked against equal_error_speedup
// itself at that error (docs/render.md §6e "What accuracy costs in time").
TEST(MatrixSpeedup, TheCeilingBoundsEveryErrorAndTheGoalsErrorReachesIt) {
  const StudyCandidate fine = candidate(1, 0.003, 0.2, 16, 8.0);
  EXPECT_EQ(speedup_ceiling(fine, fine), 1.0);
  EXPECT_EQ(error_for_speedup(fine, fine, 2.0, 3.0), std::numeric_limits<double>::infinity());
  // A quarter of the cost at equal noise: r = 4 whatever the bias.
  const StudyCandidate c = candidate(8, 0.05, 0.2, 16, 2.0);
  EXPECT_NEAR(speedup_ceiling(c, fine), 4.0, 1e-12);
  const double e3 = error_for_speedup(c, fine, 1.0, 3.0);  // b / √(1 − 3/4) = 2 b
  EXPECT_NEAR(e3, 0.1, 1e-12);
  // equal_error_speedup takes E = kMatrixErrorFraction × mean: choose the mean that puts E at e3.
  EXPECT_NEAR(equal_error_speedup(c, fine, e3 / kMatrixErrorFraction), 3.0, 1e-9);
  // Below that error it is slower than the target, above it faster, never past r.
  EXPECT_LT(equal_error_speedup(c, fine, 0.9 * e3 / kMatrixErrorFraction), 3.0);
  for (const double e : {1.1, 2.0, 10.0, 1e6}) {
    const double s = equal_error_speedup(c, fine, e * e3 / kMatrixErrorFraction);
    EXPECT_GT(s, 3.0);
    EXPECT_LE(s, speedup_ceiling(c, fine));
  }
  // r ≤ the target: never that fast, at any error, even unbiased.
  const StudyCandidate slow = candidate(8, 0.0, 0.2, 16, 4.0);  // r = 2
  EXPECT_EQ(error_for_speedup(slow, fine, 1.0, 3.0), std::numeric_limits<double>::infinity());
  EXPECT_NEAR(equal_error_speedup(slow, fine, 1e9), 2.0, 1e-12);
  // Unbiased and fast enough: the target holds at any error.
  EXPECT_EQ(error_for_speedup(candidate(8, 0.0, 0.2, 16, 1.0), fine, 1.0, 3.0), 0.0);
  // The noise counts as much as the cost: half the noise per sample at equal cost is r = 4.
  EXPECT_NEAR(speedup_ceiling(candidate(8, 0.0, 0.1, 16, 8.0), fine), 4.0, 1e-12);
}

TEST(MatrixSpec, RefusesWhatCannotRun) {
  MatrixSpec s;
  s.study.work_dir = "unused";
  s.study.spp = 2;
  EXPECT_NO_THROW(check_matrix_spec(s));
  MatrixSpec no_spp = s;
  no_spp.study.spp = 0;
  EXPECT_THROW(check_matrix_spec(no_spp), Error);
  MatrixSpec twice = s;
  twice.cloths = {"plain", "plain"};
  EXPECT_THROW(check_matrix_spec(twice), Error);
  MatrixSpec unknown = s;
  unknown.cloths = {"no-such-weave"};
  EXPECT_THROW(check_matrix_spec(unknown), Error);
  MatrixSpec tilt = s;
  tilt.tilts = {95.0};
  EXPECT_THROW(check_matrix_spec(tilt), Error);
  EXPECT_EQ(matrix_cases(s).size(), 3U * 3U * 2U);
  // Work past render::kMaxPixelSamples is refused before a cloth is made, each limit alone
  // allowing it (a 4096² film at 2²⁰ spp: about 10¹⁵ pixel samples).
  MatrixSpec huge = s;
  huge.width = huge.height = kMaxMatrixFilm;
  huge.study.spp = kMaxStudySpp;
  EXPECT_THAT(
      [&] { check_matrix_spec(huge); },
      testing::ThrowsMessage<Error>(testing::HasSubstr("pixel samples, over the limit of 1000000000000 (10^12)")));
  MatrixSpec within = s;  // the same film at 2 spp: within it
  within.width = within.height = kMaxMatrixFilm;
  EXPECT_NO_THROW(check_matrix_spec(within));
}

// A cloth, light set-up, view or memory rule given twice would render the same case or candidate
// twice under one name (docs/robustness.md "Options that would do nothing"); a cloth is its
// pattern, so an alias and its pattern are one cloth (docs/render.md §6e).
TEST(MatrixSpec, ARepeatedCaseIsRefusedAnAliasBeingItsPattern) {
  using testing::HasSubstr;
  using testing::ThrowsMessage;
  MatrixSpec s;
  s.study.work_dir = "unused";
  s.study.spp = 2;
  const auto refused = [](const MatrixSpec& bad, const std::string& what) {
    EXPECT_THAT([&] { check_matrix_spec(bad); }, ThrowsMessage<Error>(HasSubstr(what)));
  };
  MatrixSpec lights = s;
  lights.lightings = {render::ClothLighting::back, render::ClothLighting::front, render::ClothLighting::back};
  refused(lights, "render matrix: light set-up 'back' is given twice");
  MatrixSpec views = s;
  views.tilts = {45.0, 8.0, 45.0};
  refused(views, "render matrix: view at tilt 45 degrees is given twice");
  MatrixSpec twill = s;
  twill.cloths = {"twill", "plain", "twill22"};
  refused(twill, "render matrix: cloth 'twill22' (as 'twill', 'twill22') is given twice");
  MatrixSpec satin = s;
  satin.cloths = {"satin5", "satin"};
  refused(satin, "cloth 'satin5' (as 'satin', 'satin5') is given twice");
  MatrixSpec knit = s;
  knit.cloths = {"knit", "knit"};
  refused(knit, "cloth 'stockinette' (as 'knit') is given twice");
  MatrixSpec rules = s;
  rules.study.memory_rules = {transmittance::MemoryRule::segment, transmittance::MemoryRule::segment};
  refused(rules, "memory rule 'segment' is given twice");
  MatrixSpec distinct = s;
  distinct.cloths = {"knit", "twill", "satin", "plain"};
  EXPECT_NO_THROW(check_matrix_spec(distinct));
}

// A case's folder is named by its tilt in the fewest digits that read back as the same number:
// distinct views, distinct folders and CSV rows (30 and 30.00000001 shared one folder when the
// tilt was rounded to 6 digits, the second case's files over the first's).
TEST(MatrixCases, DistinctTiltsNameDistinctFolders) {
  MatrixSpec s;
  s.study.work_dir = "unused";
  s.study.spp = 2;
  s.cloths = {"plain"};
  s.lightings = {render::ClothLighting::back};
  s.tilts = {30.0, 30.00000001, 45.0, 8.0, 0.1, 30.000001, 30.0000011};
  ASSERT_NO_THROW(check_matrix_spec(s));
  const std::vector<MatrixCase> cases = matrix_cases(s);
  ASSERT_EQ(cases.size(), s.tilts.size());
  std::set<fs::path> folders;
  std::set<std::string> rows;
  for (const MatrixCase& c : cases) {
    EXPECT_EQ(std::stod(matrix_tilt_name(c.tilt)), c.tilt);  // the name reads back as the tilt
    EXPECT_EQ(c.name, "plain-back-" + matrix_tilt_name(c.tilt) + "deg");
    folders.insert(matrix_case_dir(s, c));
    MatrixCaseResult r;
    r.c = c;
    r.candidates.push_back({candidate(1, 0.0, 0.5, 16, 6.0), {}});
    const std::string csv = matrix_csv({r});
    rows.insert(csv.substr(csv.find('\n') + 1));
  }
  EXPECT_EQ(folders.size(), cases.size());
  EXPECT_EQ(rows.size(), cases.size());
  EXPECT_EQ(cases[2].name, "plain-back-45deg");  // the defaults' names as before
  EXPECT_EQ(cases[3].name, "plain-back-8deg");
  EXPECT_EQ(matrix_tilt_name(-0.0), matrix_tilt_name(0.0));
}

// An alias is its pattern in every output (as `weft gen --pattern` resolves it): the cases'
// patterns and names, matrix.csv's cloth_pattern, the headline and the --resume key.
TEST(MatrixCases, AnAliasIsItsPatternInEveryOutput) {
  MatrixSpec s;
  s.study.work_dir = "unused";
  s.study.spp = 2;
  s.cloths = {"knit", "twill"};
  s.lightings = {render::ClothLighting::back};
  s.tilts = {45.0};
  MatrixSpec canonical = s;
  canonical.cloths = {"stockinette", "twill22"};
  EXPECT_EQ(matrix_patterns(s), canonical.cloths);
  const std::vector<MatrixCase> cases = matrix_cases(s);
  ASSERT_EQ(cases.size(), 2U);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    EXPECT_EQ(cases[k].pattern, canonical.cloths[k]);
    EXPECT_EQ(cases[k].name, matrix_cases(canonical)[k].name);
  }
  EXPECT_EQ(matrix_key(s), matrix_key(canonical));
  MatrixCaseResult r;
  r.c = cases[0];
  r.candidates.push_back({candidate(1, 0.0, 0.5, 16, 6.0), {}});
  r.resolution_floors.push_back({});
  r.resolution_floors.back().factor = s.study.factors.front();
  r.resolution_floors.back().scales.blocks.push_back({});
  const std::string csv = matrix_csv({r});
  EXPECT_EQ(csv.substr(csv.find('\n') + 1).rfind(cases[0].name + ",stockinette,back,", 0), 0U) << csv;
  const std::vector<MatrixHeadline> h = matrix_headlines(s, {r});
  ASSERT_EQ(h.size(), 2U);
  EXPECT_EQ(h[0].cloth, "stockinette");
  EXPECT_EQ(h[1].cloth, "twill22");
  EXPECT_EQ(h[0].floors.size(), 1U);  // the case's floor found under its cloth's pattern
}

// A candidate's JSON is written once (study_candidate_json): the single study's report and a
// matrix case hold the same keys and values, the case without the scene path and with its memory;
// what is read back writes the same JSON again (the --resume store relies on it).
TEST(MatrixJson, ACaseHoldsTheStudysCandidateJson) {
  StudyCandidate c = candidate(4, 0.25, 0.5, 16, 3.0);
  c.name = "exponential-4x";
  c.model = "exponential";
  c.seed_a = 11;
  c.seed_b = 12;
  c.seconds = 1.5;
  c.rmse = 0.75;
  c.bias_sq = 0.0625;
  c.bias_sq_stderr = 0.01;
  c.speedup = 2.5;
  c.scene_file = "/somewhere/exponential-4x.json";
  c.memory_bytes = 999;
  c.memory_channels = 1;
  c.curve = {{1, 0.25, 0.5}, {16, 1.5, 0.75}};
  StudyCandidate fine = candidate(1, 0.0, 0.5, 16, 6.0);
  fine.name = "fine";
  fine.speedup = std::numeric_limits<double>::quiet_NaN();

  const nlohmann::json study = study_candidate_json(c);
  EXPECT_EQ(study.at("seed"), 11);
  EXPECT_EQ(study.at("second_seed"), 12);
  EXPECT_EQ(study.at("curve").at(1).at("spp"), 16);
  EXPECT_EQ(study_candidate_json(study_candidate_from_json(study)), study);
  EXPECT_TRUE(study_candidate_json(fine).at("speedup").is_null());
  EXPECT_TRUE(std::isnan(study_candidate_from_json(study_candidate_json(fine)).speedup));

  StudyResult single;
  single.candidates = {fine, c};
  EXPECT_EQ(nlohmann::json::parse(study_json(single)).at("candidates").at(1), study);

  MatrixCaseResult r;
  r.candidates.push_back({fine, {}});
  r.candidates.push_back({c, {40, 2000, 1}});
  const nlohmann::json stored = matrix_case_json(r).at("candidates").at(1);
  nlohmann::json expected = study;
  expected.erase("scene");
  expected["memory_bytes"] = 40;
  expected["memory_tree_bytes"] = 2000;
  expected["memory_channels"] = 1;
  EXPECT_EQ(stored, expected);
}

/// Bytes of every float value of the four local-field grids the medium reads (the study writes
/// only those: fit::FieldChannels::render), computed here from the fine grid.
std::uint64_t field_values(const volume::Grid& fine, int block) {
  const fit::LocalFields f = fit::local_fields(fine, block);
  std::uint64_t n = 4 * f.mean.active_voxel_count();
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_TRUE(f.variance[a].stored_as_half());
    n += 2 * f.variance[a].active_voxel_count();  // stored as half
  }
  return n;
}

TEST(MatrixRun, MemoryIsTheGridsOwnCount) {
  MatrixSpec s;
  s.cloths = {"plain"};
  s.yarns = 2;
  s.voxel_size = 0.02;
  s.lightings = {render::ClothLighting::back};
  s.tilts = {30.0};
  s.width = 16;
  s.height = 12;
  s.study.factors = {2};
  s.study.spp = 2;
  s.study.reference_spp = 16;
  s.study.work_dir = fs::path(testing::TempDir()) / "weft_render_matrix_test";
  fs::remove_all(s.study.work_dir);
  const std::vector<MatrixCaseResult> r = run_matrix(s);
  ASSERT_EQ(r.size(), 1U);
  const fs::path study = matrix_case_dir(s, r[0].c) / "study";
  fs::path cloth;
  for (const auto& e : fs::directory_iterator(s.study.work_dir / "cloths")) cloth = e.path();
  int seen = 0;
  for (const auto& c : r[0].candidates) {
    const std::string& n = c.study.name;
    if (n == "fine") {
      EXPECT_EQ(c.memory.values, 4 * volume::Grid::load(cloth).active_voxel_count());
      EXPECT_EQ(c.memory.tree, volume::Grid::load(cloth).memory_bytes());
    } else if (n == "exponential-2x") {
      EXPECT_EQ(c.memory.values, 4 * volume::Grid::load(study / "grid_2x.vdb").active_voxel_count());
      EXPECT_EQ(c.memory.channels, 1);
    } else if (n == "local-gamma-2x") {
      EXPECT_EQ(c.memory.values, field_values(volume::Grid::load(cloth), 2));
      EXPECT_EQ(c.memory.channels, 4);
    } else if (n == "shadow-directional-2x") {
      std::uint64_t values = 0;  // σ'_x, σ'_y, σ'_z: every grid of the file, counted here
      for (const volume::GridCount& g : volume::count_grids(study / "shadow_axes_2x.vdb")) {
        EXPECT_EQ(g.value_bytes, 4);  // floats
        values += 4 * g.active_voxels;
      }
      EXPECT_EQ(c.memory.values, values);
      EXPECT_EQ(c.memory.channels, 3);
    } else if (n == "slab-gamma") {
      EXPECT_EQ(c.memory.values, 12U);  // σ, C̄, Var C
    } else {
      continue;
    }
    EXPECT_GT(c.memory.values, 0U) << n;
    ++seen;
  }
  EXPECT_EQ(seen, 5);
  EXPECT_GT(r[0].cloth_pixels, 0);
  // Every candidate's family (its name without "-Nx") is one candidate_families lists, and every
  // family listed has a candidate (the albedo-corrected ones are fitted per cloth here): the
  // families --study-components takes are the study's own.
  std::set<std::string> families;
  for (const auto& c : r[0].candidates) {
    const std::string& n = c.study.name;
    families.insert(c.study.factor > 1 ? n.substr(0, n.rfind('-')) : n);
  }
  StudySpec fitted = s.study;
  fitted.albedo_fitted = true;  // as the matrix's own spec has it (default_matrix_spec)
  const std::vector<std::string> listed = candidate_families(fitted);
  EXPECT_EQ(families, std::set<std::string>(listed.begin(), listed.end()));
  // (c), the validation's best model, is chosen against the ground truth: labelled so in the
  // case's study report, under its name and under the former key (docs/render.md §6c).
  std::ifstream report_file(matrix_case_dir(s, r[0].c) / "reference.study.json");
  const nlohmann::json study_report = nlohmann::json::parse(report_file);
  EXPECT_EQ(study_report.at("best_by_ground_truth").at("uses_ground_truth"), true);
  EXPECT_FALSE(study_report.at("best_by_ground_truth").at("model").get<std::string>().empty());
  EXPECT_EQ(study_report.at("best_predictive"), study_report.at("best_by_ground_truth"));
  // A candidate is labelled only when it was itself fitted with the ground truth (§6d (b)).
  for (const auto& c : study_report.at("candidates"))
    EXPECT_EQ(c.at("uses_ground_truth"), c.at("name").get<std::string>().starts_with("albedo-corrected")) << c;
  // A grid under the cloth's name that is not that cloth (put there by hand: another spec recorded,
  // or none) is refused before anything renders, naming the file, and stays.
  for (const bool with_key : {true, false}) {
    volume::Grid other(s.voxel_size);
    other.set_value(0, 0, 0, 0.5F);
    if (with_key) other.set_metadata("weft:matrix_cloth_spec", "{}");
    fs::remove(cloth);
    other.save(cloth);
    EXPECT_THAT([&] { (void)run_matrix(s); },
                testing::ThrowsMessage<Error>(
                    testing::HasSubstr("is not the plain cloth its name says (it records " +
                                       std::string(with_key ? "another generator spec" : "no generator spec") + ")")));
    EXPECT_TRUE(fs::exists(cloth));
  }
  fs::remove_all(s.study.work_dir);
}

/// Asks to stop (Cancelled, as Ctrl-C in Python) at the first report of the matrix's cases stage
/// past `after` units, and from then on at every report.
struct StopInCase : ProgressSink {
  explicit StopInCase(std::uint64_t after) : after(after) {}
  void begin(std::string_view label, std::uint64_t /*total*/) override {
    if (stop) throw Cancelled();
    in_cases = label == kMatrixCasesStage;
  }
  void advance(std::uint64_t done) override {
    if (!stop && in_cases && done > after) {
      stop = true;
      stopped_at = done;
    }
    if (stop) throw Cancelled();
  }
  void end() noexcept override {}
  std::uint64_t after;
  std::atomic<bool> in_cases{false};
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> stopped_at{0};
};

MatrixSpec tiny_matrix(const std::string& folder) {
  MatrixSpec s;
  s.cloths = {"plain"};
  s.yarns = 2;
  s.voxel_size = 0.02;
  s.lightings = {render::ClothLighting::back};
  s.tilts = {30.0, 60.0};
  s.width = 16;
  s.height = 12;
  s.study.factors = {2};
  s.study.spp = 2;
  s.study.reference_spp = 64;
  s.study.work_dir = fs::path(testing::TempDir()) / folder;
  fs::remove_all(s.study.work_dir);
  return s;
}

// A stop asked for inside a case's renders stops that case there (its first render, the
// reference, is not finished: its scene file is written after it), reaches the caller as
// Cancelled, and stores nothing of it; the case finished before stays stored, and a rerun with
// --resume takes it and renders the other.
TEST(MatrixRun, AStopInsideACaseStopsItThereAndStoresNothingOfIt) {
  const MatrixSpec s = tiny_matrix("weft_render_matrix_stop");
  const std::vector<MatrixCase> cases = matrix_cases(s);
  ASSERT_EQ(cases.size(), 2U);
  {
    dist::UnitStore store(s.study.work_dir / "matrix.units", matrix_key(s), false);
    StopInCase sink(0);  // the first report inside case 0
    EXPECT_THROW((void)run_matrix(s, sink, &store), Cancelled);
    EXPECT_GT(sink.stopped_at.load(), 0U);
    EXPECT_LT(sink.stopped_at.load(), kMatrixCaseUnits);
    EXPECT_FALSE(store.load(0).has_value());
    EXPECT_FALSE(fs::exists(matrix_case_dir(s, cases[0]) / "study" / "reference.json"));
    EXPECT_FALSE(fs::exists(matrix_case_dir(s, cases[0]) / "reference.study.json"));
  }
  {
    dist::UnitStore store(s.study.work_dir / "matrix.units", matrix_key(s), false);
    StopInCase sink(kMatrixCaseUnits);  // inside case 1, case 0 done
    EXPECT_THROW((void)run_matrix(s, sink, &store), Cancelled);
    EXPECT_LT(sink.stopped_at.load(), 2 * kMatrixCaseUnits);
    EXPECT_TRUE(store.load(0).has_value());
    EXPECT_FALSE(store.load(1).has_value());
    EXPECT_FALSE(fs::exists(matrix_case_dir(s, cases[1]) / "study" / "reference.json"));
  }
  {
    // A case that fails in its report files, after its study kept its own folder (here a folder
    // in the way of its .study.json), leaves its folder as it was: none of the report files
    // written before the failure, none of the study's, nothing stored.
    const fs::path dir = matrix_case_dir(s, cases[1]);
    fs::remove_all(dir);
    fs::create_directories(dir / "reference.study.json");
    dist::UnitStore store(s.study.work_dir / "matrix.units", matrix_key(s), true);
    EXPECT_THROW((void)run_matrix(s, null_progress(), &store), Error);
    EXPECT_FALSE(store.load(1).has_value());
    std::vector<std::string> left;
    for (const auto& e : fs::recursive_directory_iterator(dir)) left.push_back(fs::relative(e.path(), dir).string());
    EXPECT_EQ(left, std::vector<std::string>{"reference.study.json"}) << "a half-written case folder";
    fs::remove_all(dir);
  }
  dist::UnitStore store(s.study.work_dir / "matrix.units", matrix_key(s), true);
  const std::vector<MatrixCaseResult> r = run_matrix(s, null_progress(), &store);
  EXPECT_EQ(store.found(), 1U);
  ASSERT_EQ(r.size(), 2U);
  EXPECT_TRUE(fs::exists(matrix_case_dir(s, cases[1]) / "reference.study.json"));
  fs::remove_all(s.study.work_dir);
}

}  // namespace
}  // namespace weft::study
