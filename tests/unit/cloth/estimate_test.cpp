// The cost estimate of a cloth (estimate.h) against what a build really makes, and the guard
// that refuses before anything is generated.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/estimate.h"
#include "data_gen/cloth/pattern.h"
#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/core/progress.h"
#include "weft/curves/curve_io.h"
#include "weft/volume/pass_budget.h"

namespace weft::cloth {
namespace {
namespace fs = std::filesystem;

// One continuous knitted yarn (stockinette courses joined end to end, as scripts/data/long_yarn.py
// writes it), `points` centreline points, about 0.26 mm apart.
Curve long_knit_yarn(int points) {
  const double r = 0.15;
  const double W = 6.5 * r;
  const double H = 8.0 * r;
  const double D = 1.8 * r;
  const int wales = 10;
  const int per_stitch = 16;
  Curve c;
  for (int course = 0; static_cast<int>(c.points.size()) < points; ++course) {
    for (int k = 0; k <= wales * per_stitch && static_cast<int>(c.points.size()) < points; ++k) {
      const double t = 2.0 * std::numbers::pi * k / per_stitch;
      double x = W * (t / (2.0 * std::numbers::pi) + 0.05 * std::sin(2.0 * t));
      if (course % 2 == 1) x = W * wales - x;
      c.points.push_back({x, course * H + 0.75 * H * (1.0 - std::cos(t)), D * std::cos(t)});
    }
  }
  return c;
}

void expect_within_twice(double estimate, double measured, const char* what) {
  EXPECT_GT(measured, 0.0) << what;
  EXPECT_LE(estimate, 2.0 * measured) << what << ": estimate " << estimate << ", measured " << measured;
  EXPECT_GE(estimate, 0.5 * measured) << what << ": estimate " << estimate << ", measured " << measured;
}

void check_estimate(const ClothSpec& spec) {
  const ClothBuild b = build_cloth(spec, null_progress());
  const ClothEstimate& e = b.estimate;
  SCOPED_TRACE(spec.pattern + " at " + std::to_string(spec.voxel_size) + " mm");
  expect_within_twice(static_cast<double>(e.fibers), static_cast<double>(b.fibers.size()), "fibres");
  expect_within_twice(static_cast<double>(e.fiber_points), static_cast<double>(b.fibers.points.size()), "points");
  expect_within_twice(e.fiber_length, b.fibers.length(), "fibre length");
  expect_within_twice(static_cast<double>(e.active_voxels), static_cast<double>(b.report.active_voxels),
                      "active voxels");
  expect_within_twice(static_cast<double>(e.grid_bytes), static_cast<double>(b.grid.memory_bytes()),
                      "grid memory (OpenVDB memUsage)");
}

TEST(ClothEstimate, WithinTwiceOfWhatTheBuildMakesOnThreeSizes) {
  // The built-in weave at its 10 µm voxels (≈0.56 M active voxels).
  check_estimate(default_cloth_spec());
  // A knit at 20 µm.
  ClothSpec knit = default_cloth_spec();
  knit.pattern = "stockinette";
  knit.warp_count = knit.weft_count = 3;
  knit.warp_spacing = knit.weft_spacing = knit.crimp = 0.0;
  knit.voxel_size = 0.02;
  check_estimate(resolve(knit));
  // One long imported yarn (≈ 100 mm, 5 pieces) at 25 µm.
  const fs::path file = fs::temp_directory_path() / "weft_estimate_long_yarn.obj";
  curves::write_obj_curves(file, {long_knit_yarn(400)});
  ClothSpec imported = default_cloth_spec();
  imported.pattern = "import";
  imported.input = file.string();
  imported.voxel_size = 0.025;
  check_estimate(resolve(imported));
  fs::remove(file);
}

TEST(ClothEstimate, GrowsLinearlyWithYarnLength) {
  ClothSpec spec = default_cloth_spec();
  CurveSet one;
  one.curves = {long_knit_yarn(400)};
  one.direction = {0};
  CurveSet four;
  four.curves = {long_knit_yarn(1600)};
  four.direction = {0};
  const ClothEstimate a = estimate_cloth(spec, one);
  const ClothEstimate b = estimate_cloth(spec, four);
  const double ratio = curve_length(four.curves[0]) / curve_length(one.curves[0]);
  EXPECT_NEAR(static_cast<double>(b.fiber_points) / static_cast<double>(a.fiber_points), ratio, 0.01 * ratio);
  EXPECT_NEAR(static_cast<double>(b.active_voxels) / static_cast<double>(a.active_voxels), ratio, 0.01 * ratio);
}

TEST(ClothEstimate, ProbeOfALargeWeaveMatchesItsCentrelines) {
  // 120×90 yarns: estimated on a 60×60 probe, scaled; against the estimate on all centrelines.
  ClothSpec spec = default_cloth_spec();
  spec.pattern = "twill22";
  spec.warp_count = 120;
  spec.weft_count = 90;
  spec = resolve(spec);
  const ClothEstimate probe = estimate_cloth(spec);
  const ClothEstimate full = estimate_cloth(spec, cloth_centerlines(spec));
  EXPECT_NEAR(probe.fiber_length / full.fiber_length, 1.0, 0.02);
  EXPECT_NEAR(static_cast<double>(probe.active_voxels) / static_cast<double>(full.active_voxels), 1.0, 0.02);
  EXPECT_NEAR(static_cast<double>(probe.peak_bytes) / static_cast<double>(full.peak_bytes), 1.0, 0.02);
}

TEST(ClothEstimate, RefusesOverTheBudgetBeforeGenerating) {
  ClothSpec spec = default_cloth_spec();
  spec.warp_count = spec.weft_count = 200;
  spec.max_memory_mb = 64.0;
  // The refusal is the estimate's (the voxelizer's own guard would name fibre pieces).
  EXPECT_THAT(
      [&] { (void)build_cloth(resolve(spec), null_progress()); },
      weft::test::throws_one_line_error_with({"cloth: estimated", "active voxels", "memory budget of 64.0 MiB"}))
      << "a 200x200 weave within 64 MiB";
  // An absurd scale saturates instead of overflowing.
  CurveSet huge;
  huge.curves = {Curve{{{0, 0, 0}, {1e300, 0, 0}}, false}};
  huge.direction = {0};
  const ClothEstimate e = estimate_cloth(default_cloth_spec(), huge);
  EXPECT_TRUE(e.overflow);
  // Said as an overflow, not as 2⁶⁴ − 1 fibres.
  EXPECT_THAT([&] { check_budget(e, 1ULL << 40U, FrontEnd::cli, "cloth of c.obj at input_scale 1e+300"); },
              ::testing::ThrowsMessage<Error>(::testing::AllOf(
                  ::testing::HasSubstr("cloth of c.obj at input_scale 1e+300: the estimate overflows"),
                  ::testing::Not(::testing::HasSubstr(std::to_string(~0ULL))),
                  // The loops saturate with the length: not their doing.
                  ::testing::Not(::testing::HasSubstr("loop_density")), ::testing::Not(::testing::HasSubstr("nan")))));
  EXPECT_FALSE(estimate_cloth(default_cloth_spec()).overflow);
}

// Flyaways: the loops the build draws, and the fibre length, voxels and leaves that dense loops,
// far-reaching loops and high hairs add, each within 2x of the build; the peak bounds the loops'
// memory. Small cloths at 20 µm, so that each build takes well under a second.
TEST(ClothEstimate, FlyawaysWithinTwiceOfWhatTheBuildMakes) {
  ClothSpec base = default_cloth_spec();
  base.warp_count = base.weft_count = 2;
  base.voxel_size = 0.02;
  const auto with = [&](const char* field, double value) {
    ClothSpec spec = base;
    for (YarnParams* y : {&spec.warp_yarn, &spec.weft_yarn}) {
      for (const auto& f : yarn_fields()) {
        if (std::string(f.name) == field) y->*(f.real) = value;
      }
    }
    return resolve(spec);
  };
  // Dense loops, 12 over each fibre point: past saturation.
  const ClothSpec dense = with("loop_density", 400.0);
  check_estimate(dense);
  const ClothBuild b = build_cloth(dense, null_progress());
  EXPECT_NEAR(static_cast<double>(b.estimate.loops) / static_cast<double>(b.fibers.loops), 1.0, 0.05);
  EXPECT_GT(b.estimate.plan_bytes, b.estimate.loop_bytes);
  EXPECT_GE(b.estimate.peak_bytes, b.estimate.fiber_bytes + b.estimate.loop_bytes);
  EXPECT_GT(2 * b.estimate.loop_steps, b.estimate.steps);
  // Loops whose radius spreads over tens of ply radii, and hairs that rise by 20 ply radii.
  check_estimate(with("loop_radius_sd", 30.0));
  check_estimate(with("hair_span_mean", 20.0));
}

/// Records whether any stage of work began.
class StageSink final : public ProgressSink {
 public:
  void begin(std::string_view label, std::uint64_t) override { began += std::string(label) + ";"; }
  void advance(std::uint64_t) override {}
  void end() noexcept override {}
  std::string began;
};

TEST(ClothEstimate, AHugeLoopDensityIsRefusedBeforeAnyFibreNamingIt) {
  // Memory: 1e8 loops per mm of ply are ~10⁹ loops for the 2x2 weave.
  ClothSpec spec = default_cloth_spec();
  spec.warp_count = spec.weft_count = 2;
  spec.warp_yarn.loop_density = spec.weft_yarn.loop_density = 1e8;
  StageSink sink;
  try {
    (void)build_cloth(resolve(spec), sink);
    ADD_FAILURE() << "1e8 loops per mm were accepted";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("over the memory budget"), std::string::npos) << m;
    EXPECT_NE(m.find("from --set loop_density=1e+08"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  EXPECT_EQ(sink.began, "");
  // Work: few loops (little memory) but each over 10⁹ points of its fibre (one fibre a ply, a
  // migration period of 100 m), in Python's words.
  spec.warp_yarn.loop_density = spec.weft_yarn.loop_density = 1e4;
  spec.warp_yarn.fiber_count = spec.weft_yarn.fiber_count = 1;
  spec.warp_yarn.migration_period = spec.weft_yarn.migration_period = 1e5;
  const ClothEstimate e = estimate_cloth(resolve(spec));
  EXPECT_GT(e.steps, volume::kMaxPassSteps);
  EXPECT_LT(e.peak_bytes, default_memory_budget());
  try {
    (void)build_cloth(resolve(spec), sink, false, FrontEnd::python);
    ADD_FAILURE() << "a build of " << e.steps << " steps was accepted";
  } catch (const Error& error) {
    const std::string m = error.what();
    EXPECT_NE(m.find("cloth: making the fibres would take"), std::string::npos) << m;
    EXPECT_NE(m.find("from loop_density=1e+04"), std::string::npos) << m;
  }
  EXPECT_EQ(sink.began, "");
  // The default cloth is far from both limits.
  const ClothEstimate d = estimate_cloth(default_cloth_spec());
  EXPECT_LT(d.steps, 1e-4 * volume::kMaxPassSteps);
}

}  // namespace
}  // namespace weft::cloth
