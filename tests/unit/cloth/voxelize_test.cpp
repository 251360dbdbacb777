#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <numbers>

#include "data_gen/cloth/voxelize.h"
#include "data_gen/cloth/yarn.h"
#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"

namespace weft::cloth {
namespace {

constexpr double kPi = std::numbers::pi;

FiberSet single_fiber(const Point3& a, const Point3& b, double r, int points = 2) {
  FiberSet f;
  std::vector<Point3> poly;
  for (int i = 0; i < points; ++i) {
    const double t = static_cast<double>(i) / (points - 1);
    poly.push_back({a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t});
  }
  f.add(poly, r, 0, 0, 0, FiberKind::regular);
  return f;
}

// Sum of C·h³ over each slice perpendicular to `axis`, keyed by slice index.
std::map<int, double> slice_volumes(const volume::Grid& g, int axis) {
  std::map<int, double> out;
  const auto box = g.active_bbox();
  const double h3 = std::pow(g.voxel_size(), 3);
  for (int i = box.min[0]; i <= box.max[0]; ++i) {
    for (int j = box.min[1]; j <= box.max[1]; ++j) {
      for (int k = box.min[2]; k <= box.max[2]; ++k) {
        const float v = g.value(i, j, k);
        if (v != 0.0f) out[axis == 0 ? i : axis == 1 ? j : k] += v * h3;
      }
    }
  }
  return out;
}

// A fibre along each axis, 40 voxels long, crossing leaf boundaries at every multiple of 8
// voxels. With r = 0.6 h no voxel can be covered whole (its half-diagonal is 0.707 h), so
// nothing clamps and every whole slice holds exactly πr²h: the quadrature stations are spaced
// h/4 along the axis, so each slice receives the same four stations whatever leaf it is in; a
// seam (gap or double count) at a leaf boundary would put a slice off by ≥ ¼.
class AxisFibre : public ::testing::TestWithParam<int> {};

TEST_P(AxisFibre, RightVolumeAndNoSeamsAtLeafBoundaries) {
  const int axis = GetParam();
  const double h = 0.01;
  const double r = 0.6 * h;
  Point3 a{0.0343, 0.0517, 0.0261};  // off-centre in its voxel column on purpose
  Point3 b = a;
  b[axis] += 40 * h;
  VoxelizeOptions o;
  o.voxel_size = h;
  VoxelizeReport report;
  const volume::Grid g = voxelize(single_fiber(a, b, r), o, report);
  const double exact = 40 * h * kPi * r * r;
  EXPECT_NEAR(report.fiber_volume, exact, 1e-12 * exact);
  EXPECT_EQ(report.overlap_fraction, 0.0);
  EXPECT_NEAR(report.grid_volume, exact, 1e-6 * exact);
  EXPECT_NEAR(g.sum() * h * h * h, exact, 1e-6 * exact);
  const auto slices = slice_volumes(g, axis);
  const int first = static_cast<int>(std::floor(a[axis] / h));
  int boundary_slices = 0;
  for (const auto& [index, v] : slices) {
    if (index == first || index == first + 40) continue;  // partial end slices
    EXPECT_NEAR(v, kPi * r * r * h, 1e-5 * kPi * r * r * h) << "slice " << index;
    if (index % 8 == 0 || index % 8 == 7) ++boundary_slices;
  }
  EXPECT_GE(boundary_slices, 8);  // the fibre did cross leaf boundaries
  // Nothing outside the cylinder's bounding box.
  const auto box = g.active_bbox();
  for (int c = 0; c < 3; ++c) {
    EXPECT_GE(box.min[c], static_cast<int>(std::floor((std::min(a[c], b[c]) - r) / h)));
    EXPECT_LE(box.max[c], static_cast<int>(std::floor((std::max(a[c], b[c]) + r) / h)));
  }
}

// r = h, the thickest fibre the requirement covers: voxels near the axis are covered whole, so
// quadrature noise may push a few over 1 and clamp; Σ C·h³ must stay within 1 % of Σ length·πr²
// and the clamped part is reported.
TEST_P(AxisFibre, FibreAsThickAsAVoxelKeepsVolumeWithinOnePercent) {
  const int axis = GetParam();
  const double h = 0.01;
  Point3 a{0.0343, 0.0517, 0.0261};
  Point3 b = a;
  b[axis] += 40 * h;
  VoxelizeOptions o;
  o.voxel_size = h;
  VoxelizeReport report;
  voxelize(single_fiber(a, b, h), o, report);
  const double exact = 40 * h * kPi * h * h;
  EXPECT_LT(std::abs(report.relative_error), 0.01);
  EXPECT_NEAR(report.grid_volume + report.overlap_fraction * report.fiber_volume, exact, 1e-6 * exact);
}

INSTANTIATE_TEST_SUITE_P(Axes, AxisFibre, ::testing::Values(0, 1, 2));

TEST(Voxelizer, DiagonalFibreHasRightVolumeAndSmoothSlices) {
  // Direction (3, 2, 1)/√14 through several leaves. A slice x ∈ [ih, (i+1)h) of an oblique
  // cylinder holds πr²h/|d_x|. The quadrature puts stations len/m ≤ h/8 apart along the axis, so
  // a slice gets its share to within one station on each side: |error| ≤ 2·(h/8)·|d_x|/h of the
  // slice volume (disk points spread the stations further, making it smaller); a seam would be
  // off by far more.
  const double h = 0.01;
  const double r = 0.8 * h;
  const Point3 a{0.003, 0.0071, -0.0113};
  const double len = 60 * h;
  const double n = std::sqrt(14.0);
  const Point3 b{a[0] + len * 3 / n, a[1] + len * 2 / n, a[2] + len * 1 / n};
  VoxelizeOptions o;
  o.voxel_size = h;
  o.samples_per_voxel = 8;
  VoxelizeReport report;
  const volume::Grid g = voxelize(single_fiber(a, b, r, 7), o, report);
  const double exact = len * kPi * r * r;
  EXPECT_NEAR(report.grid_volume, exact, 1e-6 * exact);
  const double dx = 3 / n;
  const double slice = kPi * r * r * h / dx;
  const double tol = 2.0 * (h / 8) * dx / h;
  // Interior slices: away from the ends by the cap's extent r·tan + a voxel.
  const double margin = r * std::sqrt(1 - dx * dx) / dx + h;
  int checked = 0;
  for (const auto& [i, v] : slice_volumes(g, 0)) {
    if (i * h < a[0] + margin || (i + 1) * h > b[0] - margin) continue;
    EXPECT_NEAR(v, slice, tol * slice) << "slice " << i;
    ++checked;
  }
  EXPECT_GE(checked, 30);
}

TEST(Voxelizer, VoxelValuesMatchAnIndependentOverlapEstimate) {
  // Reference: each voxel's overlap with the (capless) cylinder by 12³ midpoint samples of the
  // voxel. The quadrature moves volume at most ~δ = h/n across the fibre surface, so the
  // misplaced fraction Σ|C − C_ref|·h³ / V is bounded by (surface · δ)/V = 2δ/r (+ the
  // reference's own h/12 resolution, 2(h/12)/r); per voxel, |C − C_ref| stays well below 1.
  const double h = 0.01;
  const double r = 0.8 * h;
  const int n = 8;
  const Point3 a{0.0031, 0.0072, -0.0114};
  const Point3 b{0.2031, 0.1272, 0.0486};
  VoxelizeOptions o;
  o.voxel_size = h;
  o.samples_per_voxel = n;
  VoxelizeReport report;
  const volume::Grid g = voxelize(single_fiber(a, b, r), o, report);
  Point3 d{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (double& v : d) v /= len;
  const auto inside = [&](double x, double y, double z) {
    const double px = x - a[0], py = y - a[1], pz = z - a[2];
    const double t = px * d[0] + py * d[1] + pz * d[2];
    if (t < 0.0 || t >= len) return false;
    const double qx = px - t * d[0], qy = py - t * d[1], qz = pz - t * d[2];
    return qx * qx + qy * qy + qz * qz < r * r;
  };
  double misplaced = 0.0;
  double worst = 0.0;
  constexpr int m = 12;
  for (int i = static_cast<int>(std::floor((std::min(a[0], b[0]) - r) / h));
       i <= std::floor((std::max(a[0], b[0]) + r) / h); ++i) {
    for (int j = static_cast<int>(std::floor((std::min(a[1], b[1]) - r) / h));
         j <= std::floor((std::max(a[1], b[1]) + r) / h); ++j) {
      for (int k = static_cast<int>(std::floor((std::min(a[2], b[2]) - r) / h));
           k <= std::floor((std::max(a[2], b[2]) + r) / h); ++k) {
        int hits = 0;
        for (int u = 0; u < m; ++u) {
          for (int v = 0; v < m; ++v) {
            for (int w = 0; w < m; ++w)
              hits += inside((i + (u + 0.5) / m) * h, (j + (v + 0.5) / m) * h, (k + (w + 0.5) / m) * h) ? 1 : 0;
          }
        }
        const double ref = static_cast<double>(hits) / (m * m * m);
        const double err = std::abs(g.value(i, j, k) - ref);
        misplaced += err * h * h * h;
        worst = std::max(worst, err);
      }
    }
  }
  const double volume = len * kPi * r * r;
  EXPECT_LT(misplaced / volume, 2.0 * (h / n) / r + 2.0 * (h / m) / r);
  EXPECT_LT(worst, 0.5);
  std::cout << "misplaced fraction " << misplaced / volume << ", worst voxel error " << worst << "\n";
}

TEST(Voxelizer, InscribedFibreFillsPiOverFourOfItsColumn) {
  // r = h/2 centred on a voxel column: every quadrature point lies inside the column, so each
  // voxel holds exactly the disc area fraction π/4.
  const double h = 0.02;
  const Point3 a{5.5 * h, 9.5 * h, 0.0};
  const Point3 b{5.5 * h, 9.5 * h, 24 * h};
  VoxelizeOptions o;
  o.voxel_size = h;
  VoxelizeReport report;
  const volume::Grid g = voxelize(single_fiber(a, b, 0.5 * h), o, report);
  EXPECT_EQ(g.active_voxel_count(), 24U);
  for (int k = 0; k < 24; ++k) EXPECT_NEAR(g.value(5, 9, k), kPi / 4, 1e-6) << k;
}

TEST(Voxelizer, OverlappingFibresClampAtOneAndReportTheLoss) {
  const double h = 0.01;
  const double r = 3 * h;
  FiberSet f = single_fiber({0.001, 0.002, 0.003}, {0.301, 0.002, 0.003}, r);
  f.append(f);  // the same fibre twice: every voxel inside would hold C = 2
  VoxelizeOptions o;
  o.voxel_size = h;
  VoxelizeReport report;
  const volume::Grid g = voxelize(f, o, report);
  const auto box = g.active_bbox();
  float max_value = 0.0f;
  for (int i = box.min[0]; i <= box.max[0]; ++i) {
    for (int j = box.min[1]; j <= box.max[1]; ++j) {
      for (int k = box.min[2]; k <= box.max[2]; ++k) max_value = std::max(max_value, g.value(i, j, k));
    }
  }
  EXPECT_EQ(max_value, 1.0f);
  const double exact = 2 * 0.3 * kPi * r * r;
  EXPECT_NEAR(report.fiber_volume, exact, 1e-9 * exact);
  EXPECT_GT(report.overlap_fraction, 0.2);  // most of the doubled core is clamped away
  EXPECT_LT(report.overlap_fraction, 0.5);  // never more than the second copy
  EXPECT_NEAR(report.grid_volume + report.overlap_fraction * report.fiber_volume, exact, 1e-6 * exact);
  EXPECT_NEAR(report.relative_error, -report.overlap_fraction, 1e-6);
}

TEST(Voxelizer, RealYarnConservesVolume) {
  // A cotton yarn (fibre radius 6 µm) voxelized at h = 10 µm ≥ r: Σ C·h³ equals Σ length·πr²
  // within 1 % (clamped overlap aside, which is reported and added back here).
  const YarnParams y = yarn_preset("cotton");
  Curve c;
  for (int i = 0; i <= 20; ++i) c.points.push_back({0.05 * i, 0.1 * std::sin(0.3 * i), 0.05 * std::cos(0.2 * i)});
  const FiberSet f = yarn_fibers(c, y, 4, 0);
  VoxelizeOptions o;
  o.voxel_size = 0.01;
  VoxelizeReport report;
  const volume::Grid g = voxelize(f, o, report);
  EXPECT_NEAR(report.fiber_volume, f.volume(), 1e-12 * f.volume());
  EXPECT_LT(std::abs(report.relative_error), 0.01);
  EXPECT_NEAR(report.grid_volume + report.overlap_fraction * report.fiber_volume, report.fiber_volume,
              1e-5 * report.fiber_volume);
  EXPECT_EQ(report.fiber_count, f.size());
  EXPECT_EQ(report.active_voxels, g.active_voxel_count());
  EXPECT_EQ(g.metadata().at("units"), "mm");
}

TEST(Voxelizer, EachFibreKeepsItsOwnRadiusAndLength) {
  // Pieces are named by (point index, run) and rebuilt from the fibres when a leaf is filled:
  // the fibre of a point and the runs of a long segment must come back right. Three fibres far
  // apart, of different radii, one with a repeated (zero-length) point and one single segment
  // 40 voxels long (10 runs of 4 voxels): the volume in each fibre's own box is its πr²L.
  const double h = 0.01;
  FiberSet f;
  f.add({{0.0, 0.0, 0.0}, {0.05, 0.01, 0.0}, {0.05, 0.01, 0.0}, {0.1, 0.03, 0.01}}, 0.4 * h, 0, 0, 0,
        FiberKind::regular);
  f.add({{0.0, 1.0, 0.0}, {0.4, 1.0, 0.0}}, 0.9 * h, 0, 0, 1, FiberKind::regular);
  f.add({{1.0, 0.0, 0.0}, {1.0, 0.0, 0.1}, {1.02, 0.05, 0.15}}, 0.6 * h, 0, 0, 2, FiberKind::hair);
  VoxelizeOptions o;
  o.voxel_size = h;
  VoxelizeReport report;
  const volume::Grid g = voxelize(f, o, report);
  ASSERT_EQ(report.overlap_fraction, 0.0);  // r < h/√2: nothing clamps
  const std::array<std::array<int, 2>, 3> x_range{{{-5, 20}, {-5, 50}, {90, 110}}};
  const std::array<std::array<int, 2>, 3> y_range{{{-5, 10}, {90, 110}, {-5, 15}}};
  for (std::size_t n = 0; n < f.size(); ++n) {
    FiberSet one;
    std::vector<Point3> poly(f.points.begin() + static_cast<std::ptrdiff_t>(f.offsets[n]),
                             f.points.begin() + static_cast<std::ptrdiff_t>(f.offsets[n + 1]));
    one.add(poly, f.radius[n], 0, 0, 0, FiberKind::regular);
    double in_box = 0.0;
    for (int i = x_range[n][0]; i <= x_range[n][1]; ++i) {
      for (int j = y_range[n][0]; j <= y_range[n][1]; ++j) {
        for (int k = -5; k <= 20; ++k) in_box += g.value(i, j, k) * h * h * h;
      }
    }
    // float values: relative rounding ~1e-7 per voxel
    EXPECT_NEAR(in_box, one.volume(), 1e-5 * one.volume()) << "fibre " << n;
  }
}

TEST(Voxelizer, SameGridForAnyThreadCount) {
  const FiberSet f = yarn_fibers(Curve{{{0, 0, 0}, {0.6, 0.05, 0.02}}, false}, yarn_preset("wool"), 8, 0);
  VoxelizeOptions o;
  o.voxel_size = 0.012;
  VoxelizeReport r1, r2;
  volume::Grid g1, g2;
  {
    const ThreadLimit one(1);
    g1 = voxelize(f, o, r1);
  }
  {
    const ThreadLimit two(2);
    g2 = voxelize(f, o, r2);
  }
  EXPECT_EQ(r1.grid_volume, r2.grid_volume);
  ASSERT_EQ(g1.active_voxel_count(), g2.active_voxel_count());
  const auto box = g1.active_bbox();
  for (int i = box.min[0]; i <= box.max[0]; ++i) {
    for (int j = box.min[1]; j <= box.max[1]; ++j) {
      for (int k = box.min[2]; k <= box.max[2]; ++k) ASSERT_EQ(g1.value(i, j, k), g2.value(i, j, k));
    }
  }
}

TEST(Voxelizer, BadVoxelSizesAndMemoryBudgetAreRefusedBeforeAllocating) {
  const FiberSet f = single_fiber({0, 0, 0}, {1, 0, 0}, 0.01);
  VoxelizeReport report;
  VoxelizeOptions o;
  for (double bad : {0.0, -0.01, std::nan("")}) {
    o.voxel_size = bad;
    EXPECT_THAT([&] { voxelize(f, o, report); }, ::testing::ThrowsMessage<Error>(::testing::HasSubstr("voxel_size")))
        << bad;
  }
  o.voxel_size = 1e-5;
  o.max_memory_bytes = 1 << 20;  // 1 MiB
  EXPECT_THAT([&] { voxelize(f, o, report); },
              weft::test::throws_one_line_error_with({"memory budget", "(--max-memory)"}));
  // Asked from Python, the budget is named in Python's words.
  o.asker = FrontEnd::python;
  EXPECT_THAT([&] { voxelize(f, o, report); },
              ::testing::ThrowsMessage<Error>(::testing::AllOf(::testing::HasSubstr("(max_memory_mb=)"),
                                                               ::testing::Not(::testing::HasSubstr("--")))));
  o.asker = FrontEnd::cli;
  // Absurdly small voxels are refused by the cheap bound (no per-piece pass, no allocation).
  o.voxel_size = 1e-12;
  o.max_memory_bytes = 0;
  EXPECT_THROW(voxelize(f, o, report), Error);
  EXPECT_GT(default_memory_budget(), 0U);
  // The estimate bounds what a run really makes.
  o.voxel_size = 0.01;
  const auto e = estimate_voxelize_memory(f, o);
  const volume::Grid g = voxelize(f, o, report);
  EXPECT_GE(e.leaves * 512, g.active_voxel_count());
  EXPECT_THROW(voxelize(FiberSet{}, o, report), Error);
}

}  // namespace
}  // namespace weft::cloth
