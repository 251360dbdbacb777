// The index range of a grid (volume/grid.h, kMaxIndex; docs/robustness.md "Index range"): OpenVDB's
// dense copies step from node to node by origin + node size, which overflows int32 in the
// outermost root child, so every entry point that takes an index refuses one beyond the range in
// one line, and the last index inside it is copied both ways exactly.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include <openvdb/io/File.h>

#include "counting_sink.h"
#include "error_matchers.h"
#include "weft/core/progress.h"
#include "weft/core/rng.h"
#include "weft/volume/dense.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

using test::throws_one_line_error_with;

constexpr int kBeyond = kMaxIndex + 1;  // the origin of the outermost root child

TEST(IndexRange, TheLastIndexIsCopiedBothWays) {
  for (const int edge : {kMaxIndex, -kMaxIndex}) {
    Grid g(0.5);
    g.set_value(0, 1, edge, 0.25F);
    const IndexBox box{{0, 1, edge}, {0, 1, edge}};
    EXPECT_EQ(to_dense(g, box, 1024), std::vector<float>{0.25F});
    Grid h(0.5);
    const float v = 0.75F;
    from_dense(h, {edge, 0, 0}, {1, 1, 1}, &v);
    EXPECT_EQ(h.value(edge, 0, 0), 0.75F);
    EXPECT_EQ(h.active_voxel_count(), 1U);
  }
}

// OpenVDB's parallel copyToDense split its box at (min + max) >> 1 in int32 arithmetic, which
// overflowed (SIGSEGV) for every box with |min + max| > 2^31 - 1: found by a tester from
// i = 2^30 - 1 up to the range's end and from its start to -2^31 + 10^6. Each such place, on each
// axis, in both layouts: the dense copy holds exactly the voxels written there.
TEST(IndexRange, ADenseCopyFarFromZeroHoldsTheVoxels) {
  constexpr std::int64_t kN = 8;
  std::vector<float> values(kN * kN * kN);
  Pcg32 rng = stream_for(11, 0);
  for (float& v : values) v = 0.01F + static_cast<float>(rng.uniform());  // > 0: every voxel active
  for (const int far : {(1 << 30) - 1, 1 << 30, 2147483647 - 4200, kMaxIndex - static_cast<int>(kN) + 1,
                        -2147483647 - 1 + 5000, -2147483647 - 1 + 1000000, -kMaxIndex}) {
    for (int axis = 0; axis < 3; ++axis) {
      std::array<int, 3> min{-3, 5, 0};
      min.at(static_cast<std::size_t>(axis)) = far;
      Grid g(0.5);
      from_dense(g, min, {kN, kN, kN}, values.data());
      const IndexBox box = g.active_bbox();
      ASSERT_EQ(box.min, min);
      EXPECT_EQ(to_dense(g, box, dense_bytes(box)), values) << "x-major at " << far << " along axis " << axis;
      // Fortran order of the same [i][j][k] array.
      std::vector<float> z_major(values.size());
      copy_to_dense(g, box, z_major.data(), DenseLayout::z_major);
      for (std::int64_t i = 0; i < kN; ++i)
        for (std::int64_t j = 0; j < kN; ++j)
          for (std::int64_t k = 0; k < kN; ++k)
            ASSERT_EQ(z_major[static_cast<std::size_t>((k * kN + j) * kN + i)],
                      values[static_cast<std::size_t>((i * kN + j) * kN + k)])
                << "z-major at " << far << " along axis " << axis;
    }
  }
}

TEST(IndexRange, ADenseCopyStopsAtItsProgressSinksCancel) {
  Grid g(0.5);
  g.set_value(0, 0, 0, 0.5F);
  const IndexBox box{{0, 0, 0}, {63, 3, 63}};  // 8 slabs of 8 along either layout's slowest axis
  std::vector<float> out(static_cast<std::size_t>(dense_bytes(box) / sizeof(float)));
  for (const DenseLayout layout : {DenseLayout::x_major, DenseLayout::z_major}) {
    test::CountingSink sink(2);
    EXPECT_THROW(copy_to_dense(g, box, out.data(), layout, sink), Cancelled);
  }
}

TEST(IndexRange, ADenseCopyBeyondItIsRefused) {
  Grid g(0.5);
  g.set_value(0, 0, 0, 0.5F);
  // One voxel at 2^31 - 1, one at the first index of the outermost child, and two from below -kMaxIndex.
  for (const IndexBox& box :
       {IndexBox{{2147483647, 0, 0}, {2147483647, 0, 0}}, IndexBox{{0, 0, kBeyond}, {0, 0, kBeyond}},
        IndexBox{{0, -kBeyond, 0}, {0, -kBeyond + 1, 0}}}) {
    EXPECT_THAT([&] { (void)to_dense(g, box, 1U << 20U); },
                throws_one_line_error_with({"dense copy", "index box", "2147479551"}));
    std::vector<float> out(static_cast<std::size_t>(dense_bytes(box) / sizeof(float)));
    EXPECT_THAT([&] { copy_to_dense(g, box, out.data()); }, throws_one_line_error_with({"dense copy", "2147479551"}));
  }
}

TEST(IndexRange, AnArrayReachingBeyondItIsRefusedBeforeAnyVoxelIsWritten) {
  const std::vector<float> ones(8, 1.0F);
  for (const std::array<int, 3>& origin : {std::array<int, 3>{2147483647, 0, 0}, std::array<int, 3>{0, kMaxIndex, 0},
                                           std::array<int, 3>{0, 0, -kBeyond}}) {
    Grid g(0.5);
    EXPECT_THAT(
        [&] {
          from_dense(g, origin, {2, 2, 2}, ones.data());
        },
        throws_one_line_error_with({"index_origin", "2147479551"}));
    EXPECT_EQ(g.active_voxel_count(), 0U);
  }
}

TEST(IndexRange, SetValueBeyondItIsRefused) {
  Grid g(0.5);
  EXPECT_THAT([&] { g.set_value(kBeyond, 0, 0, 1.0F); }, throws_one_line_error_with({"set_value", "2147479551"}));
  EXPECT_THAT([&] { g.set_value(0, 0, -2147483647 - 1, 1.0F); }, throws_one_line_error_with({"set_value"}));
  EXPECT_EQ(g.active_voxel_count(), 0U);
}

TEST(IndexRange, AFileWithAVoxelBeyondItIsRefused) {
  ensure_openvdb_initialized();
  const auto path = std::filesystem::temp_directory_path() / "weft_index_range_far.vdb";
  auto grid = openvdb::FloatGrid::create(0.0F);
  grid->setName("density");
  grid->tree().setValue(openvdb::Coord(0, kBeyond + 5, 0), 0.5F);
  openvdb::io::File(path.string()).write({grid});
  EXPECT_THAT(
      [&] { (void)Grid::load(path); },
      throws_one_line_error_with({path.string(), "grid 'density'", "active voxels", "2147479557", "2147479551"}));
  // The same voxel inside the range is read.
  grid->tree().clear();
  grid->tree().setValue(openvdb::Coord(0, kMaxIndex, 0), 0.5F);
  openvdb::io::File(path.string()).write({grid});
  EXPECT_EQ(Grid::load(path).value(0, kMaxIndex, 0), 0.5F);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace weft::volume
