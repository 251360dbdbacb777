// Grids stored as 16-bit floats (Grid::store_as_half): the values are rounded once, in memory,
// so a file gives back exactly what was rendered or measured, at 2 bytes a value.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <openvdb/openvdb.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <string>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

TEST(HalfPrecision, RoundsToTheNearestHalfWithinItsUnitRoundoff) {
  // IEEE half: 11 significant bits, so above the smallest normal (2⁻¹⁴) the rounding error is at
  // most 2⁻¹¹ of the value, and a value already on half's lattice is kept exactly.
  Pcg32 rng(7);
  for (int n = 0; n < 100000; ++n) {
    const float v = std::ldexp(static_cast<float>(1.0 + rng.uniform()), static_cast<int>(rng.uniform() * 29.0) - 14);
    const float h = half_precision(v);
    EXPECT_LE(std::abs(h - v), std::ldexp(std::abs(v), -11)) << v;
    EXPECT_EQ(half_precision(h), h) << v;
    // No half lies strictly nearer: the neighbours one half-ulp away are no closer.
    const float ulp = std::ldexp(1.0F, std::ilogb(h) - 10);
    EXPECT_GE(std::abs(h + ulp - v), std::abs(h - v)) << v;
    EXPECT_GE(std::abs(h - ulp - v), std::abs(h - v)) << v;
  }
  EXPECT_EQ(half_precision(0.0F), 0.0F);
  EXPECT_EQ(half_precision(65504.0F), 65504.0F);
  EXPECT_TRUE(std::isinf(half_precision(1.0e5F)));
  // Below 2⁻¹⁴ half is subnormal: a fixed absolute step of 2⁻²⁴.
  EXPECT_LE(std::abs(half_precision(3.0e-7F) - 3.0e-7F), std::ldexp(1.0F, -25));
}

TEST(HalfStorage, AFileGivesBackTheRoundedValuesAtTwoBytesEach) {
  ensure_openvdb_initialized();
  const auto dir = std::filesystem::temp_directory_path();
  Grid g(0.1, "var_concentration_x");
  Pcg32 rng(11);
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) g.set_value(i, j, i % 5, static_cast<float>(0.25 * rng.uniform()));
  }
  g.impl().grid->tree().addTile(1, openvdb::Coord(64, 0, 0), 0.123456789F, true);  // a tile is rounded too
  Grid full = Grid(0.1, "full");
  for (auto it = g.impl().grid->cbeginValueOn(); it; ++it) {
    if (it.isVoxelValue()) full.set_value(it.getCoord().x(), it.getCoord().y(), it.getCoord().z(), *it);
  }
  EXPECT_FALSE(g.stored_as_half());
  EXPECT_EQ(g.value_bytes(), 4);
  const float before = g.value(3, 4, 3);
  g.store_as_half();
  EXPECT_TRUE(g.stored_as_half());
  EXPECT_EQ(g.value_bytes(), 2);
  EXPECT_EQ(g.value(3, 4, 3), half_precision(before));
  EXPECT_EQ(g.value(70, 1, 1), half_precision(0.123456789F));

  const auto half_path = dir / "weft_half_storage.vdb";
  const auto full_path = dir / "weft_half_storage_full.vdb";
  g.save(half_path);
  full.save(full_path);
  const Grid back = Grid::load(half_path);
  EXPECT_TRUE(back.stored_as_half());
  EXPECT_EQ(back.active_voxel_count(), g.active_voxel_count());
  for (auto it = g.impl().grid->cbeginValueOn(); it; ++it) {
    const openvdb::Coord c = it.getCoord();
    EXPECT_EQ(std::bit_cast<std::uint32_t>(back.value(c.x(), c.y(), c.z())), std::bit_cast<std::uint32_t>(*it));
  }
  const std::vector<GridCount> counts = count_grids(half_path);
  ASSERT_EQ(counts.size(), 1U);
  EXPECT_EQ(counts[0].value_bytes, 2);
  EXPECT_EQ(count_grids(full_path)[0].value_bytes, 4);
  // The 1600 voxels' values take 2 bytes each in the file instead of 4 (OpenVDB compresses
  // buffers by default; random values do not compress much).
  EXPECT_LT(std::filesystem::file_size(half_path) + 2000, std::filesystem::file_size(full_path));
  std::filesystem::remove(half_path);
  std::filesystem::remove(full_path);
}

TEST(HalfStorage, AValueBeyondHalfsRangeIsRefusedAndNothingChanges) {
  Grid g(0.1, "alpha_x");
  g.set_value(0, 0, 0, 0.3F);
  g.set_value(5, 0, 0, 1.0e6F);
  EXPECT_THAT([&] { g.store_as_half(); }, weft::test::throws_one_line_error_with({"alpha_x", "65504"}))
      << "a value of 10⁶ must be refused";
  EXPECT_FALSE(g.stored_as_half());
  EXPECT_EQ(g.value(0, 0, 0), 0.3F);
  EXPECT_EQ(g.value(5, 0, 0), 1.0e6F);
}

TEST(HalfStorage, SetValueKeepsAHalfGridHalfAndRefusesValuesBeyondIt) {
  Grid g(0.1, "var_concentration_x");
  g.set_value(0, 0, 0, 0.3F);
  g.store_as_half();
  g.set_value(1, 0, 0, 0.123456789F);  // kept as its file gives it back
  EXPECT_EQ(g.value(1, 0, 0), half_precision(0.123456789F));
  g.set_value(2, 0, 0, kHalfMax);  // the range's end is in it
  EXPECT_EQ(g.value(2, 0, 0), kHalfMax);
  EXPECT_THAT([&] { g.set_value(3, 0, 0, 70000.0F); },
              weft::test::throws_one_line_error_with({"var_concentration_x", "70000", "65504", "(3, 0, 0)"}));
  EXPECT_EQ(g.active_voxel_count(), 3U) << "a refused value must leave the grid as it was";
  // A float grid keeps any float.
  Grid f(0.1, "full");
  f.set_value(0, 0, 0, 70000.123F);
  EXPECT_EQ(f.value(0, 0, 0), 70000.123F);
}

// A writer never writes what its reader refuses for what the writing did: a value put into the tree by any
// other way than set_value (an OpenVDB accessor, as the library's own loops use) is caught when
// the file is written, with the file, the grid, the voxel and the value named and nothing written.
TEST(HalfStorage, AFileThatItsReaderWouldRefuseIsNotWritten) {
  ensure_openvdb_initialized();
  const auto path = std::filesystem::temp_directory_path() / "weft_half_storage_refused.vdb";
  std::filesystem::remove(path);
  Grid half(0.1, "var_concentration_y");
  half.set_value(0, 0, 0, 0.25F);
  half.store_as_half();
  half.impl().grid->getAccessor().setValue(openvdb::Coord(4, 5, 6), 70000.0F);  // half: +inf
  const std::initializer_list<std::string> refused = {"weft_half_storage_refused.vdb", "var_concentration_y", "70000",
                                                      "(4, 5, 6)", "65504"};
  EXPECT_THAT([&] { half.save(path); }, weft::test::throws_one_line_error_with(refused));
  EXPECT_FALSE(std::filesystem::exists(path));
  Grid mean(0.1, "mean_concentration");
  mean.set_value(0, 0, 0, 0.5F);
  EXPECT_THAT([&] { save_grids({mean, half}, path); }, weft::test::throws_one_line_error_with(refused));
  EXPECT_FALSE(std::filesystem::exists(path));
  Grid far(0.1, "density");
  far.impl().grid->getAccessor().setValue(openvdb::Coord(kMaxIndex + 1, 0, 0), 0.5F);  // set_value refuses it
  EXPECT_THAT([&] { far.save(path); }, weft::test::throws_one_line_error_with({"not written", "index range"}));
  EXPECT_FALSE(std::filesystem::exists(path));

  // Just inside the range the file is written and read back as it was held.
  half.impl().grid->getAccessor().setValue(openvdb::Coord(4, 5, 6), kHalfMax);
  save_grids({mean, half}, path);
  EXPECT_EQ(Grid::load(path, "var_concentration_y").value(4, 5, 6), kHalfMax);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace weft::volume
