// The voxel ground truth converges to the fibres' (docs/validate.md §Voxelization error): two
// crossing layers of opaque fibres (one along x, one slanted) voxelized at r, r/2 and r/4: T_gt of
// the opaque voxel rule approaches T_fibre on the same rays on every axis, the linear rule (σC)
// does not.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "data_gen/cloth/grid_fibres.h"
#include "data_gen/cloth/voxelize.h"
#include "weft/fibres/fibre_beam.h"
#include "weft/volume/beam.h"
#include "weft/volume/voxel_rule.h"

namespace weft::cloth {
namespace {

constexpr double kRadius = 0.02;

FiberSet two_layers() {
  FiberSet f;
  for (int m = 0; m < 4; ++m) {
    f.add({{-0.1, 0.05 + 0.1 * m, 0.07}, {0.5, 0.05 + 0.1 * m, 0.07}}, kRadius, 0, 0, m, FiberKind::regular);
    // A slanted crossing layer: rays of the x and y beams see its fibres at every angle.
    f.add({{0.03 + 0.1 * m, -0.1, 0.12}, {0.09 + 0.1 * m, 0.5, 0.14}}, kRadius, 1, 0, m, FiberKind::regular);
  }
  return f;
}

/// RMS over depths and the three axes of T_gt − T_fibre.
double voxelization_error(const FiberSet& fibers, double h, volume::VoxelRule rule) {
  VoxelizeOptions vo;
  vo.voxel_size = h;
  VoxelizeReport report;
  const volume::Grid grid = voxelize(fibers, vo, report, null_progress());
  const double sigma = 2.0 / (std::numbers::pi * kRadius);
  const volume::Grid mu = volume::extinction_grid(grid, sigma, rule);
  const fibres::CapsuleIndex index(fibre_geometry(fibers));
  double sq = 0.0;
  for (int a = 0; a < 3; ++a) {
    volume::BeamSpec spec;
    spec.direction = {0, 0, 0};
    spec.direction[static_cast<std::size_t>(a)] = 1.0;
    const auto voxel = volume::measure_beam(mu, spec);
    const auto fibre = fibres::measure_fibre_beam(index, grid, spec);
    const double rms = fibres::curve_difference(voxel, fibre).rms;
    sq += rms * rms / 3.0;
  }
  return std::sqrt(sq);
}

TEST(FibreConvergence, OpaqueVoxelRuleConvergesToTheFibres) {
  const FiberSet fibers = two_layers();
  const double coarse = voxelization_error(fibers, kRadius, volume::VoxelRule::opaque);
  const double medium = voxelization_error(fibers, kRadius / 2, volume::VoxelRule::opaque);
  const double fine = voxelization_error(fibers, kRadius / 4, volume::VoxelRule::opaque);
  const double linear_fine = voxelization_error(fibers, kRadius / 4, volume::VoxelRule::linear);
  RecordProperty("errors", std::to_string(coarse) + " " + std::to_string(medium) + " " + std::to_string(fine) +
                               " linear " + std::to_string(linear_fine));
  // Edge voxels are a fraction ∝ h/r of the rays that meet a fibre: first order in h would halve
  // the error per halving; 0.7 allows the rays that run along a fibre's edge (x beam here).
  EXPECT_LT(medium, 0.7 * coarse);
  EXPECT_LT(fine, 0.7 * medium);
  // σC gives a fibre an optical depth ≈ 1 along its mean chord: far from opaque.
  EXPECT_GT(linear_fine, 3.0 * fine);
}

}  // namespace
}  // namespace weft::cloth
