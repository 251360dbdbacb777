// Downsampling conserves what the grid holds (volume fraction × volume), block by block, for any
// extent, alignment and tile; thinned beams keep the same columns whatever the tracing method.
#include <gtest/gtest.h>

#include <openvdb/openvdb.h>

#include <cmath>
#include <map>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/volume/beam.h"
#include "weft/volume/downsample.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

// The coarse index of a fine one, by floating point: independent of the library's integer floor_div.
int block(int i, int f) { return static_cast<int>(std::floor(static_cast<double>(i) / f)); }

/// A sparse random grid with odd extents straddling negative indices.
Grid random_grid(std::uint64_t seed) {
  Grid g(0.25);
  g.set_origin({0.1, -0.3, 0.7});
  Pcg32 rng(seed, 7);
  for (int i = -5; i < 12; ++i) {
    for (int j = -9; j < 4; ++j) {
      for (int k = 3; k < 22; ++k) {
        if (rng.uniform() < 0.4) g.set_value(i, j, k, static_cast<float>(rng.uniform()));
      }
    }
  }
  return g;
}

TEST(Downsample, ConservesTheTotalToFloatRounding) {
  const Grid fine = random_grid(3);
  const double total = fine.sum();
  ASSERT_GT(total, 100.0);
  for (int f : {1, 2, 3, 4, 5, 8, 16}) {
    const Grid coarse = downsample(fine, f);
    EXPECT_DOUBLE_EQ(coarse.voxel_size(), fine.voxel_size() * f);
    // Index 0 at the anchor, the active box's lower corner (volume/block_lattice.h).
    const IndexBox box = fine.active_bbox();
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(coarse.origin()[a], fine.origin()[a] + box.min[a] * fine.voxel_size(), 1e-12);
    const double cells = static_cast<double>(f) * f * f;
    // Each coarse value is a double mean rounded once to float: relative error ≤ 2^−24 each.
    EXPECT_NEAR(coarse.sum() * cells, total, total * std::ldexp(1.0, -23)) << "factor " << f;
  }
}

TEST(Downsample, EveryBlockIsTheMeanOfItsFineVoxelsWithEmptyOnesAsZero) {
  const Grid fine = random_grid(8);
  for (int f : {2, 3, 4}) {
    std::map<std::array<int, 3>, double> sums;
    const IndexBox box = fine.active_bbox();
    for (int i = box.min[0]; i <= box.max[0]; ++i) {
      for (int j = box.min[1]; j <= box.max[1]; ++j) {
        for (int k = box.min[2]; k <= box.max[2]; ++k) {
          sums[{block(i - box.min[0], f), block(j - box.min[1], f), block(k - box.min[2], f)}] += fine.value(i, j, k);
        }
      }
    }
    const Grid coarse = downsample(fine, f);
    for (const auto& [key, s] : sums) {
      EXPECT_FLOAT_EQ(coarse.value(key[0], key[1], key[2]), static_cast<float>(s / (f * f * f)))
          << "factor " << f << " block " << key[0] << "," << key[1] << "," << key[2];
    }
    // Blocks straddling the box: the non-divisible extents leave partly empty coarse voxels.
    const IndexBox cbox = coarse.active_bbox();
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(cbox.min[a], 0);
      EXPECT_EQ(cbox.max[a], block(box.max[a] - box.min[a], f));
    }
  }
}

TEST(Downsample, ActiveTilesCountWithTheirOverlap) {
  Grid fine(1.0);
  // A whole leaf-sized tile plus voxels: the tile is split across blocks of 3.
  fine.impl().grid->fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(7)), 0.5f, true);
  fine.set_value(9, 1, 1, 1.0f);
  const double total = fine.sum();
  EXPECT_DOUBLE_EQ(total, 0.5 * 512 + 1.0);
  const Grid coarse = downsample(fine, 3);
  EXPECT_NEAR(coarse.sum() * 27.0, total, total * 1e-7);
  EXPECT_FLOAT_EQ(coarse.value(0, 0, 0), 0.5f);                 // 27 tile voxels
  EXPECT_FLOAT_EQ(coarse.value(2, 2, 2), 0.5f * 8.0f / 27.0f);  // indices 6..7 on each axis
  EXPECT_FLOAT_EQ(coarse.value(3, 0, 0), 1.0f / 27.0f);
}

TEST(Downsample, RejectsEmptyGridsAndBadFactors) {
  const Grid empty(1.0);
  EXPECT_THROW((void)downsample(empty, 2), Error);
  const Grid fine = random_grid(1);
  EXPECT_THROW((void)downsample(fine, 0), Error);
  EXPECT_THROW((void)downsample(fine, -2), Error);
  EXPECT_THROW((void)downsample(fine, 5000), Error);
}

// The block means of a grid are its downsample; one cell changed, a cell left out where the fine
// voxels hold something, a cell added where they hold nothing, or the blocks moved by a voxel are
// each found, at that cell.
TEST(BlockMeanMismatch, FindsTheCellThatIsNotTheMeanOfItsVoxels) {
  const Grid fine = random_grid(5);
  for (int f : {1, 2, 3}) {
    const Grid coarse = downsample(fine, f);
    EXPECT_FALSE(block_mean_mismatch(coarse, fine).has_value()) << "factor " << f;
    const IndexBox box = coarse.active_bbox();
    const std::array<int, 3> mid{(box.min[0] + box.max[0]) / 2, (box.min[1] + box.max[1]) / 2,
                                 (box.min[2] + box.max[2]) / 2};
    Grid changed = coarse.deep_copy();
    const float v = coarse.value(mid[0], mid[1], mid[2]);
    changed.set_value(mid[0], mid[1], mid[2], v * 1.01f + 0.01f);
    const auto m = block_mean_mismatch(changed, fine);
    ASSERT_TRUE(m.has_value()) << "factor " << f;
    EXPECT_EQ(m->index, mid);
    EXPECT_NEAR(m->fine_mean, v, 1e-6);
    EXPECT_NEAR(m->coarse, v * 1.01f + 0.01f, 1e-6);
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(m->centre[a], coarse.origin()[a] + coarse.voxel_size() * (mid[a] + 0.5), 1e-12);
    // A cell past the grid's voxels.
    Grid grown = coarse.deep_copy();
    grown.set_value(box.max[0] + 2, mid[1], mid[2], 0.25f);
    EXPECT_TRUE(block_mean_mismatch(grown, fine).has_value()) << "factor " << f;
    // The fine voxels moved by one: other blocks (f = 1: every value beside its neighbour's).
    Grid moved = fine.deep_copy();
    moved.set_origin({fine.origin()[0] + fine.voxel_size(), fine.origin()[1], fine.origin()[2]});
    EXPECT_TRUE(block_mean_mismatch(coarse, moved).has_value()) << "factor " << f;
  }
  // A cell of the fine grid's cloth left out.
  Grid part(fine.voxel_size() * 2);
  const Grid whole = downsample(fine, 2);
  part.set_origin(whole.origin());
  const IndexBox wbox = whole.active_bbox();
  for (int i = wbox.min[0]; i <= wbox.max[0]; ++i)
    for (int j = wbox.min[1]; j <= wbox.max[1]; ++j)
      for (int k = wbox.min[2]; k <= wbox.max[2]; ++k)
        if (k < wbox.max[2] && whole.value(i, j, k) > 0.0f) part.set_value(i, j, k, whole.value(i, j, k));
  EXPECT_TRUE(block_mean_mismatch(part, fine).has_value());
}

TEST(Beam, ThinnedBeamKeepsTheSameColumnsForEveryMethod) {
  const Grid g = random_grid(5);
  for (int axis = 0; axis < 3; ++axis) {
    BeamSpec spec;
    spec.direction = {0.0, 0.0, 0.0};
    spec.direction[static_cast<std::size_t>(axis)] = axis == 1 ? -1.0 : 1.0;
    spec.scale = 2.0;
    spec.seed = 17;
    spec.method = BeamMethod::streaming;
    const TransmittanceCurve all = measure_beam(g, spec);
    spec.column_stride = 2;
    const TransmittanceCurve a = measure_beam(g, spec);
    spec.method = BeamMethod::per_ray;
    const TransmittanceCurve b = measure_beam(g, spec);
    ASSERT_EQ(a.rays, b.rays);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_NEAR(a.log_t[k], b.log_t[k], 1e-12 * (1.0 + std::abs(a.log_t[k])));
      EXPECT_NEAR(a.rel_stderr[k], b.rel_stderr[k], 1e-9);
    }
    // One column per 2×2 cell: a quarter of the rays, up to the cells cut by the face's edge.
    const auto e = g.active_bbox().extent();
    const auto cells = static_cast<std::uint64_t>(((e[(axis + 1) % 3] + 1) / 2) * ((e[(axis + 2) % 3] + 1) / 2));
    EXPECT_LE(a.rays, cells);
    EXPECT_GE(a.rays, all.rays / 4 - (e[(axis + 1) % 3] + e[(axis + 2) % 3]));
    spec.column_stride = 0;
    EXPECT_THROW((void)measure_beam(g, spec), Error);
  }
}

}  // namespace
}  // namespace weft::volume
