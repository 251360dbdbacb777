// The column reader's sparse read column by column (volume/columns.h, read_columns) holds exactly
// the dense read's voxels of non-zero value, each column in depth order, along every axis.
#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "weft/core/rng.h"
#include "weft/volume/columns.h"
#include "weft/volume/grid.h"

namespace weft::volume {
namespace {

/// A sparse random grid straddling negative indices, a fifth of its active voxels of value 0
/// (active but empty: the read leaves them out).
Grid random_grid(std::uint64_t seed) {
  Grid g(0.5);
  Pcg32 rng(seed, 11);
  for (int i = -13; i < 9; ++i) {
    for (int j = -4; j < 19; ++j) {
      for (int k = -7; k < 10; ++k) {
        const double u = rng.uniform();
        if (u < 0.1) {
          g.set_value(i, j, k, 0.0f);
        } else if (u < 0.5) {
          g.set_value(i, j, k, static_cast<float>(rng.uniform()) + 0.01f);
        }
      }
    }
  }
  return g;
}

TEST(Columns, ReadColumnsHoldsTheDenseNonZeroVoxelsInDepthOrder) {
  const Grid g = random_grid(5);
  for (int axis = 0; axis < 3; ++axis) {
    const ColumnReader reader(g, axis);
    ColumnTile dense;
    SparseColumns cols;
    std::size_t voxels = 0;
    for (std::size_t tile = 0; tile < reader.tile_count(); ++tile) {
      reader.read(tile, dense);
      ASSERT_TRUE(reader.read_columns(tile, cols)) << "axis " << axis << " patch " << tile;
      ASSERT_EQ(cols.u0, dense.u0);
      ASSERT_EQ(cols.v0, dense.v0);
      ASSERT_EQ(cols.nu, dense.nu);
      ASSERT_EQ(cols.nv, dense.nv);
      ASSERT_EQ(cols.depth, dense.depth);
      for (int iu = 0; iu < dense.nu; ++iu) {
        for (int iv = 0; iv < dense.nv; ++iv) {
          std::vector<std::pair<int, float>> want;
          const float* col = dense.column(iu, iv);
          for (int k = 0; k < dense.depth; ++k) {
            if (col[k] != 0.0f) want.emplace_back(k, col[k]);
          }
          const auto c = static_cast<std::size_t>(iu * cols.nv + iv);
          std::vector<std::pair<int, float>> got;
          for (std::uint32_t j = 0; j < cols.count[c]; ++j) {
            const std::size_t at = c * static_cast<std::size_t>(cols.depth) + j;
            got.emplace_back(cols.k[at], cols.value[at]);
          }
          EXPECT_EQ(got, want) << "axis " << axis << " patch " << tile << " column " << c;
          voxels += got.size();
        }
      }
    }
    EXPECT_GT(voxels, 1000U) << "axis " << axis;
  }
}

}  // namespace
}  // namespace weft::volume
