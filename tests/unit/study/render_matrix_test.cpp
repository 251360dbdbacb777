// The study matrix (render_matrix.h, render_matrix_report.h): the equal-error speed-up against its
// formula, and every representation's memory against the grids' own counts on a tiny run.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "weft/core/error.h"
#include "weft/fit/local_fields.h"
#include "weft/study/render_matrix.h"
#include "weft/study/render_matrix_report.h"
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
}

/// Bytes of every float value of the four local-field grids the medium reads (the study writes
/// only those: fit::FieldChannels::render), computed here from the fine grid.
std::uint64_t field_values(const volume::Grid& fine, int block) {
  const fit::LocalFields f = fit::local_fields(fine, block);
  std::uint64_t n = 4 * f.mean.active_voxel_count();
  for (std::size_t a = 0; a < 3; ++a) n += 4 * f.variance[a].active_voxel_count();
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
      for (const volume::GridCount& g : volume::count_grids(study / "shadow_axes_2x.vdb"))
        values += 4 * g.active_voxels;
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
  fs::remove_all(s.study.work_dir);
}

}  // namespace
}  // namespace weft::study
