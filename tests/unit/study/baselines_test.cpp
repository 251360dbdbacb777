// The study's baselines (docs/render.md §6d) on a small cube of grid medium: the new candidates
// appear with their memory and labels, the self-shadowing correction changes nothing where no
// block shadows itself (a uniform grid renders the exponential-Nx image bit for bit), and the
// albedo fit reaches its target within its tolerance on the scene it is fitted on.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/progress.h"
#include "weft/render/scene.h"
#include "weft/study/albedo_fit.h"
#include "weft/study/render_study.h"
#include "weft/study/render_study_report.h"
#include "weft/study/representation_memory.h"
#include "weft/volume/grid.h"

namespace weft::study {
namespace {

namespace fs = std::filesystem;

/// A fresh folder, removed with everything in it when the test ends.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      // The process id keeps concurrent runs (another build tree, ctest -j) apart.
      : path(fs::temp_directory_path() / fmt::format("weft_baselines_test_{}_{}", name, ::getpid())) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

/// The cube [−0.5, 0.5]³ as 16³ voxels of concentration `c(i, j, k)`, in a lit scene.
render::SceneDesc cube_scene(const fs::path& dir, const std::function<float(int, int, int)>& c) {
  volume::Grid g(1.0 / 16.0);
  g.set_origin({-0.5, -0.5, -0.5});
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j)
      for (int k = 0; k < 16; ++k)
        if (const float v = c(i, j, k); v > 0.0F) g.set_value(i, j, k, v);
  const fs::path file = dir / "cube.vdb";
  g.save(file);
  const std::string text = fmt::format(R"({{
    "camera": {{"position": [0.9, 1.1, 2.4], "look_at": [0, 0, 0], "fov": 40, "width": 20, "height": 20}},
    "integrator": {{"spp": 8, "max_depth": 64, "rr_depth": 5, "seed": 3}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"cloth": {{"type": "grid", "file": "{}", "sigma": 8, "albedo": [0.8, 0.7, 0.6], "g": 0.3}}}},
    "shapes": [{{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "boundary",
                 "interior": "cloth"}}],
    "lights": [{{"type": "environment", "radiance": 0.3}}, {{"type": "point", "position": [1, 2, 1], "intensity": 3}}]
  }})",
                                       file.string());
  return render::parse_scene(text, "baselines test", dir);
}

StudySpec small_spec(const fs::path& dir) {
  StudySpec s;
  s.factors = {2, 4};
  s.spp = 8;
  s.reference_spp = 64;
  s.scale = "extent";
  s.work_dir = dir / "study";
  return s;
}

const StudyCandidate& candidate(const StudyResult& r, const std::string& name) {
  for (const auto& c : r.candidates)
    if (c.name == name) return c;
  throw Error("no candidate " + name);
}

/// Yarn-like columns along z (2×2 voxels dense, 2 voxels of gap), offset by one voxel from the
/// blocks so that blocks of 2 and 4 both hold dense and empty columns and shadow themselves.
float columns(int i, int j, int /*k*/) { return ((i + 1) % 4 < 2 && (j + 1) % 4 < 2) ? 1.0F : 0.0F; }

TEST(StudyBaselines, NewCandidatesAppearWithMemoryAndLabels) {
  const TempDir tmp("appear");
  const fs::path& dir = tmp.path;
  const render::SceneDesc scene = cube_scene(dir, columns);
  StudySpec spec = small_spec(dir);
  spec.albedo_factors = {{4, 1.2}};
  const StudyResult r = run_study(scene, spec);
  for (const int f : {2, 4}) {
    const StudyCandidate& sc = candidate(r, fmt::format("shadow-corrected-{}x", f));
    const StudyCandidate& ex = candidate(r, fmt::format("exponential-{}x", f));
    EXPECT_EQ(sc.model, "shadow-corrected");
    EXPECT_EQ(sc.memory_channels, 1);
    EXPECT_GT(sc.memory_bytes, 0U);
    EXPECT_FALSE(sc.fitted_to_images);
    // Gaps through the blocks: the corrected grid lets more light through, a different image.
    EXPECT_NE(sc.image.rgb, ex.image.rgb);
    EXPECT_EQ(candidate(r, fmt::format("local-gamma-{}x", f)).memory_channels, 4);
  }
  EXPECT_THROW((void)candidate(r, "albedo-corrected-2x"), Error);  // no k for 2x
  const StudyCandidate& al = candidate(r, "albedo-corrected-4x");
  EXPECT_TRUE(al.fitted_to_images);
  EXPECT_DOUBLE_EQ(al.albedo_factor, 1.2);
  EXPECT_EQ(al.memory_bytes, candidate(r, "exponential-4x").memory_bytes);
  // The corrected albedo is in the candidate's scene, clamped to 1 (0.8 × 1.2 = 0.96, …).
  const render::SceneDesc s = render::load_scene(al.scene_file);
  EXPECT_NEAR(s.media.at("cloth").albedo[0], 0.96, 1e-12);
  EXPECT_NEAR(s.media.at("cloth").albedo[2], 0.72, 1e-12);
  EXPECT_EQ(candidate(r, "fine").memory_channels, 1);
  // The slab's law: its parameters, one float each, no tree (the matrix's count: one rule).
  EXPECT_EQ(candidate(r, "slab-gamma").memory_bytes, 4U * candidate(r, "slab-gamma").memory_channels);
  EXPECT_GT(candidate(r, "slab-gamma").memory_channels, 0);
  // The values a grid holds, not OpenVDB's tree, which moves with the index origin.
  const StudyCandidate& fine = candidate(r, "fine");
  EXPECT_EQ(fine.memory_bytes,
            4 * volume::Grid::load(render::load_scene(fine.scene_file).media.begin()->second.file,
                                   render::load_scene(fine.scene_file).media.begin()->second.grid_name)
                    .active_voxel_count());
  EXPECT_GT(fine.memory_tree_bytes, fine.memory_bytes);
  // The reports carry the new fields.
  const nlohmann::json j = nlohmann::json::parse(study_json(r));
  bool seen = false;
  for (const auto& c : j["candidates"]) {
    if (c["name"] != "albedo-corrected-4x") continue;
    seen = true;
    EXPECT_EQ(c["fitted_to_images"], true);
    EXPECT_EQ(c["uses_ground_truth"], true);
    EXPECT_DOUBLE_EQ(c["albedo_factor"].get<double>(), 1.2);
  }
  EXPECT_TRUE(seen);
  EXPECT_NE(study_csv(r).find(",memory_bytes,memory_channels,albedo_factor,fitted_to_images,"), std::string::npos);
  // The study's folder moves whole: its scenes name the files it made relative to themselves,
  // the fine grid (outside it) by its absolute path.
  const fs::path moved = dir / "moved";
  fs::rename(spec.work_dir, moved);
  const render::SceneDesc replay = render::load_scene(moved / "shadow-corrected-4x.json");
  EXPECT_EQ(fs::path(replay.media.at("cloth").file), moved / "shadow_4x.vdb");
  EXPECT_TRUE(fs::exists(replay.media.at("cloth").file));
  EXPECT_EQ(render::load_scene(moved / "fine.json").media.at("cloth").file, (dir / "cube.vdb").string());
}

/// Records the stages a study reports and the last count of each.
struct StageLog : ProgressSink {
  void begin(std::string_view label, std::uint64_t total) override {
    const std::lock_guard lock(mutex);
    stages.push_back({std::string(label), total, 0});
  }
  void advance(std::uint64_t done) override {
    const std::lock_guard lock(mutex);
    stages.back().done = std::max(stages.back().done, done);
  }
  void end() noexcept override {}
  struct Stage {
    std::string label;
    std::uint64_t total;
    std::uint64_t done;
  };
  std::mutex mutex;
  std::vector<Stage> stages;
};

// With a fixed spp every render of the study (reference, its components, background, A, B and
// their components) reports into one stage of pixel samples (render_study.h), the last stage,
// which ends at exactly its total: no render uncounted or counted twice (docs/render.md §6c).
TEST(StudyProgress, TheRendersAreOneStageThatEndsAtItsTotal) {
  const TempDir tmp("progress");
  const render::SceneDesc scene = cube_scene(tmp.path, columns);
  StudySpec spec = small_spec(tmp.path);
  spec.factors = {2};
  spec.spp = 2;
  spec.reference_spp = 16;
  spec.components = {"exponential"};
  spec.albedo_factors = {{2, 1.1}};
  StageLog log;
  (void)run_study(scene, spec, log);
  ASSERT_FALSE(log.stages.empty());
  const StageLog::Stage& last = log.stages.back();
  EXPECT_EQ(last.label, kStudyRendersStage);
  EXPECT_GT(last.total, 20U * 20U * 16U);
  EXPECT_EQ(last.done, last.total);
  for (std::size_t i = 0; i + 1 < log.stages.size(); ++i) EXPECT_NE(log.stages[i].label, kStudyRendersStage);
}

TEST(StudyBaselines, ShadowCorrectedEqualsExponentialOnAUniformGrid) {
  // No block shadows itself (every column equally deep): the same coarse grid, the same image.
  const TempDir tmp("uniform");
  const fs::path& dir = tmp.path;
  const render::SceneDesc scene = cube_scene(dir, [](int, int, int) { return 0.4F; });
  const StudyResult r = run_study(scene, small_spec(dir));
  for (const int f : {2, 4}) {
    const StudyCandidate& sc = candidate(r, fmt::format("shadow-corrected-{}x", f));
    const StudyCandidate& ex = candidate(r, fmt::format("exponential-{}x", f));
    ASSERT_FALSE(sc.image.rgb.empty());
    EXPECT_EQ(sc.image.rgb, ex.image.rgb) << f << "x";
    EXPECT_EQ(sc.memory_bytes, ex.memory_bytes);
  }
}

TEST(StudyBaselines, AlbedoFitReachesItsTargetOnTheFittedScene) {
  const TempDir tmp("fit");
  const fs::path& dir = tmp.path;
  const render::SceneDesc scene = cube_scene(dir, columns);
  const StudySpec spec = small_spec(dir);
  const std::vector<AlbedoFit> fits = fit_albedo(scene, spec);
  ASSERT_EQ(fits.size(), 2U);
  for (const AlbedoFit& f : fits) {
    EXPECT_TRUE(f.converged) << f.factor << "x: k " << f.k << ", " << f.fitted << " vs " << f.target;
    EXPECT_LE(std::abs(f.fitted - f.target), f.tolerance);
    EXPECT_GT(f.tolerance, 0.0);
    EXPECT_LE(f.renders, 10);
    EXPECT_GT(f.k, 0.0);
  }
  const auto pairs = fit_albedo_factors(scene, spec, null_progress());
  ASSERT_EQ(pairs.size(), 2U);
  EXPECT_EQ(pairs[0].first, 2);
  EXPECT_DOUBLE_EQ(pairs[0].second, fits[0].k);  // deterministic: same seeds, same steps
}

TEST(StudyBaselines, CorrectedAlbedoIsClampedPerChannel) {
  const render::Rgb a = corrected_albedo(render::Rgb(0.5, 0.9, 0.0), 1.5);
  EXPECT_DOUBLE_EQ(a[0], 0.75);
  EXPECT_DOUBLE_EQ(a[1], 1.0);
  EXPECT_DOUBLE_EQ(a[2], 0.0);
}

TEST(StudyBaselines, BadAlbedoFactorsAreRefused) {
  StudySpec s;
  s.work_dir = "x";
  s.factors = {2, 4};
  s.albedo_factors = {{8, 1.1}};  // not a factor of the study
  EXPECT_THROW(check_study_spec(s), Error);
  s.albedo_factors = {{2, 0.0}};
  EXPECT_THROW(check_study_spec(s), Error);
  s.albedo_factors = {{2, 1.1}, {2, 1.2}};
  EXPECT_THROW(check_study_spec(s), Error);
  s.albedo_factors = {{2, 1.1}, {4, 0.9}};
  EXPECT_NO_THROW(check_study_spec(s));
}

TEST(StudyBaselines, AlbedoFactorsPastTheLastChannelAreRefusedWithTheScene) {
  const TempDir dir("albedo_k_max");
  const render::SceneDesc scene = cube_scene(dir.path, [](int, int, int) { return 0.5F; });
  const double k_max = albedo_k_max(scene.media.at("cloth").albedo);
  EXPECT_DOUBLE_EQ(k_max, 1.0 / 0.6);  // the darkest channel of (0.8, 0.7, 0.6) reaches 1 last
  StudySpec s = small_spec(dir.path);
  s.albedo_factors = {{2, 1.5}};  // clamps two channels (by design), not the third
  EXPECT_NO_THROW(check_study_scene(scene, s));
  s.albedo_factors = {{2, std::stod(fmt::format("{:.6g}", k_max))}};  // as --study-albedo fit prints it
  EXPECT_NO_THROW(check_study_scene(scene, s));
  for (const double k : {k_max * 1.001, 100.0, 1e300}) {
    s.albedo_factors = {{2, k}};
    EXPECT_THROW(check_study_scene(scene, s), Error) << k;
  }
}

TEST(StudyBaselines, AFactorWhoseOneVoxelHoldsTheWholeGridIsRefused) {
  // Active box 16 x 5 x 3 voxels: factors below 16 leave at least two coarse voxels along x.
  volume::Grid g(0.1);
  for (int i = 3; i < 19; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = -1; k < 2; ++k) g.set_value(i, j, k, 0.5F);
  EXPECT_NO_THROW(check_factors_for_grid({2, 15}, g));
  EXPECT_THROW(check_factors_for_grid({2, 16}, g), Error);
  EXPECT_THROW(check_factors_for_grid({4096}, g), Error);
  EXPECT_THAT([&] { check_factors_for_grid({64}, g); },
              weft::test::throws_one_line_error_with({"coarsening factor 64", "16x5x3 voxels"}));
}

TEST(StudyBaselines, DefaultFactorsTooCoarseForASmallGridAreLeftOutGivenOnesRefused) {
  volume::Grid g(0.1);  // active box 16 x 5 x 3 voxels, as above
  for (int i = 3; i < 19; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = -1; k < 2; ++k) g.set_value(i, j, k, 0.5F);
  StudySpec s;  // the defaults 2, 4, 8, 16: 16 would be one voxel
  std::vector<std::string> said;
  s.log = [&](const std::string& line) { said.push_back(line); };
  EXPECT_EQ(factors_for_grid(s, g), (std::vector<int>{2, 4, 8}));
  ASSERT_EQ(said.size(), 1U);
  EXPECT_NE(said[0].find("16 left out"), std::string::npos) << said[0];
  s.factors_given = true;  // the same factors asked for: refused, not trimmed
  EXPECT_THROW((void)factors_for_grid(s, g), Error);
  s.factors = {2, 4};
  EXPECT_EQ(factors_for_grid(s, g), (std::vector<int>{2, 4}));
  s.factors_given = false;  // no default fits: refused, saying what would
  s.factors = {16, 32};
  EXPECT_THROW((void)factors_for_grid(s, g), Error);
  s.factors = {2, 16};  // an albedo factor on a default that is left out
  s.albedo_factors = {{16, 1.1}};
  EXPECT_THROW((void)factors_for_grid(s, g), Error);
}

TEST(StudyBaselines, AnyAlbedoFactorIsTakenForAMediumThatDoesNotScatter) {
  const TempDir dir("albedo_zero");
  render::SceneDesc scene = cube_scene(dir.path, [](int, int, int) { return 0.5F; });
  scene.media.at("cloth").albedo = render::Rgb(0.0, 0.0, 0.0);
  StudySpec s = small_spec(dir.path);
  s.albedo_factors = {{2, 1.5}};  // 0 × k stays 0: nothing clamps
  EXPECT_NO_THROW(check_study_scene(scene, s));
}

// σ = 0 leaves the cloth without extinction: refused with the scene's key before any work (it
// was said as validate's "sigma must be finite and > 0" after the study had begun).
TEST(StudyBaselines, AZeroSigmaIsRefusedWithItsKey) {
  const TempDir dir("sigma_zero");
  render::SceneDesc scene = cube_scene(dir.path, [](int, int, int) { return 0.5F; });
  scene.media.at("cloth").sigma = 0.0;
  EXPECT_THAT(
      [&] { check_study_scene(scene, small_spec(dir.path)); },
      testing::ThrowsMessage<Error>(testing::HasSubstr("study: media.cloth.sigma is 0: the study needs sigma > 0")));
}

// A representation's memory is its own medium's: the scene's other media (a fog, another grid)
// are not counted into it.
TEST(StudyBaselines, TheMemoryOfARepresentationIsItsMediumsAlone) {
  const TempDir dir("memory_one_medium");
  (void)cube_scene(dir.path, [](int i, int, int) { return i < 8 ? 0.5F : 0.0F; });  // writes cube.vdb
  const fs::path scene = dir.path / "two_media.json";
  std::ofstream(scene) << fmt::format(R"({{
    "camera": {{"position": [0, 0, 4], "look_at": [0, 0, 0], "width": 4, "height": 4}},
    "materials": {{"b": {{"type": "null"}}}},
    "media": {{"cloth": {{"type": "grid", "file": "{}", "sigma": 8}},
               "fog": {{"law": {{"name": "gamma", "mean_extinction": 1, "alpha": 2}}}}}},
    "shapes": [{{"type": "box", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5], "material": "b", "interior": "cloth"}},
               {{"type": "sphere", "center": [3, 0, 0], "radius": 1, "material": "b", "interior": "fog"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]}})",
                                      (dir.path / "cube.vdb").string());
  const RepresentationMemory cloth = representation_memory(scene, "cloth");
  EXPECT_EQ(cloth.channels, 1);
  EXPECT_EQ(cloth.values, 4U * volume::Grid::load(dir.path / "cube.vdb").active_voxel_count());
  const RepresentationMemory fog = representation_memory(scene, "fog");
  EXPECT_EQ(fog.values, 4U * static_cast<std::uint64_t>(fog.channels));
  EXPECT_EQ(fog.tree, 0U);
  EXPECT_THROW((void)representation_memory(scene, "none"), Error);
}

// A scene with nothing that emits renders black everywhere: refused before anything renders, by
// name, not after the reference as an empty cloth mask blamed on the camera or the noise. An
// emitting shape alone is a light.
TEST(StudyBaselines, ASceneWithoutLightIsRefusedBeforeAnythingRenders) {
  const TempDir dir("no_light");
  render::SceneDesc scene = cube_scene(dir.path, [](int, int, int) { return 0.5F; });
  for (auto& light : scene.lights) light.intensity = render::Rgb(0.0, 0.0, 0.0);  // lights that emit nothing
  EXPECT_THAT([&] { check_study_scene(scene, small_spec(dir.path)); },
              testing::ThrowsMessage<Error>(testing::HasSubstr("study: the scene has no light that emits")));
  scene.lights.clear();
  EXPECT_THAT([&] { check_study_scene(scene, small_spec(dir.path)); },
              testing::ThrowsMessage<Error>(testing::HasSubstr("study: the scene has no light that emits")));
  render::ShapeDesc panel;
  panel.kind = render::ShapeKind::rectangle;
  panel.material = "boundary";
  panel.emission = render::Rgb(1.0, 1.0, 1.0);
  scene.shapes.push_back(panel);
  EXPECT_NO_THROW(check_study_scene(scene, small_spec(dir.path)));
}

}  // namespace
}  // namespace weft::study
