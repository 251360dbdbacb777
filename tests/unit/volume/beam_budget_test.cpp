// The size checks of beams and column passes (docs/robustness.md "Work and memory budgets"):
// refused up front with weft::Error naming the grid, never std::bad_alloc or a hang; progress
// reported (so Ctrl-C seen) per bounded amount of work; depth counts and directions at the ends
// of the double range.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>

#include "../error_of.h"
#include "counting_sink.h"
#include "weft/core/error.h"
#include "weft/core/progress.h"
#include "weft/volume/beam.h"
#include "weft/volume/columns.h"
#include "weft/volume/grid.h"
#include "weft/volume/lattice.h"
#include "weft/volume/pass_budget.h"

namespace weft::volume {
namespace {

using weft::test::error_of;

/// Two voxels 10⁶ voxels apart on every axis: a box of 10¹⁸ voxels around two active ones.
Grid far_apart() {
  Grid g(0.01, "far");
  g.set_value(0, 0, 0, 0.5F);
  g.set_value(1000000, 1000000, 1000000, 0.5F);
  return g;
}

/// A 4×3×6 block of concentration 0.5.
Grid small_block() {
  Grid g(1.0, "block");
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 6; ++k) g.set_value(i, j, k, 0.5F);
    }
  }
  return g;
}

TEST(BeamBudget, FarApartVoxelsAreRefusedBeforeAllocating) {
  const Grid g = far_apart();
  BeamSpec axis;
  axis.direction = {0, 0, 1};
  const std::string a = error_of([&] { (void)measure_beam(g, axis); });
  EXPECT_NE(a.find("grid 'far'"), std::string::npos) << a;
  EXPECT_NE(a.find("memory budget"), std::string::npos) << a;
  BeamSpec oblique;
  oblique.direction = {1, 1, 1};
  const std::string o = error_of([&] { (void)measure_beam(g, oblique); });
  EXPECT_NE(o.find("grid 'far'"), std::string::npos) << o;
  EXPECT_NE(o.find("steps"), std::string::npos) << o;
  for (int ax = 0; ax < 3; ++ax) {
    const std::string c = error_of([&] { const ColumnReader reader(g, ax); });
    EXPECT_NE(c.find("grid 'far'"), std::string::npos) << c;
  }
  // The estimate itself is cheap and finite.
  const BeamCost cost = estimate_beam(g, oblique);
  EXPECT_GT(cost.steps, kMaxPassSteps);
  EXPECT_TRUE(std::isfinite(cost.bytes));
}

TEST(BeamBudget, HugeRayCountsAreRefusedUpFront) {
  const Grid g = small_block();
  BeamSpec spec;
  spec.direction = {1, 1, 1};
  spec.rays_per_column = 2'000'000'000;
  const std::string m = error_of([&] { (void)measure_beam(g, spec); });
  EXPECT_NE(m.find("grid 'block'"), std::string::npos) << m;
  EXPECT_NE(m.find("over the limit"), std::string::npos) << m;
  // Just under the limit the estimate says so: the rule is the estimate against kMaxPassSteps.
  spec.rays_per_column = 1000;
  EXPECT_LT(estimate_beam(g, spec).steps, kMaxPassSteps);
}

using test::CountingSink;

TEST(BeamBudget, ProgressIsReportedPerBoundedWorkNotPerRowOfCells) {
  const Grid g = small_block();
  BeamSpec spec;
  spec.direction = {1, 1, 1};
  spec.rays_per_column = 20000;
  const BeamCost cost = estimate_beam(g, spec);
  CountingSink sink;
  (void)measure_beam(g, spec, sink);
  // A report every ~2²⁰ steps of a thread (beam_profiles_impl.h); a report per row of cells
  // would be ~10 here whatever the rays per column.
  EXPECT_GE(static_cast<double>(sink.reports()), cost.steps / std::ldexp(1.0, 22)) << cost.steps;
  CountingSink stopper(2);
  EXPECT_THROW((void)measure_beam(g, spec, stopper), Cancelled);
}

TEST(BeamBudget, DepthCountsBeyondAnyIntegerAreRefused) {
  const Grid g = small_block();
  for (double step : {1e-9, 1e-20, 1e-300, 5e-324}) {
    BeamSpec spec;
    spec.depth_step = step;
    const std::string m = error_of([&] { (void)measure_beam(g, spec); });
    EXPECT_NE(m.find("too fine"), std::string::npos) << step << ": " << m;
  }
  EXPECT_THROW((void)beam_depth_count(1.0, 1e-300), Error);
  EXPECT_EQ(beam_depth_count(1.0, 0.25), 5U);
}

TEST(BeamBudget, DirectionsAtTheEndsOfTheDoubleRangeHaveALength) {
  const double r = 1.0 / std::sqrt(2.0);
  const auto big = unit_direction({1e308, 1e308, 0.0}, "test");
  EXPECT_NEAR(big[0], r, 1e-15);
  EXPECT_NEAR(big[1], r, 1e-15);
  EXPECT_EQ(big[2], 0.0);
  EXPECT_EQ(unit_direction({1e-320, 0.0, 0.0}, "test"), (std::array<double, 3>{1, 0, 0}));
  EXPECT_NO_THROW((void)parse_direction("1e308,1e308,0"));
  EXPECT_NO_THROW((void)parse_direction("-1e-320,0,0"));
  EXPECT_THROW((void)parse_direction("0,0,0"), Error);
  // The same beam as its unit direction, to the last bit.
  const Grid g = small_block();
  BeamSpec huge;
  huge.direction = {1e308, 1e308, 0.0};
  BeamSpec unit;
  unit.direction = {1.0, 1.0, 0.0};
  const TransmittanceCurve a = measure_beam(g, huge);
  const TransmittanceCurve b = measure_beam(g, unit);
  EXPECT_EQ(a.log_t, b.log_t);
  EXPECT_EQ(direction_label(huge.direction), direction_label(unit.direction));
}

}  // namespace
}  // namespace weft::volume
