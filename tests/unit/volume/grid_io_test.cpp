// .vdb files through Grid::save and Grid::load, and the pre-check of check_vdb_file
// (docs/robustness.md "Fuzzing", finding 4): valid files of any size and compressibility are read
// back exactly; corrupt counts are still refused before OpenVDB allocates them; an origin too far
// for OpenVDB to copy the voxel size is refused when set, and copies keep it where OpenVDB rounds.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/voxel_rule.h"

#include "file_size_limit.h"

namespace weft::volume {
namespace {

enum class Fill { Constant, Binary, Random };

/// An n³ block of voxels: one value, a checkerboard of 0 and 1, or uniform random values.
Grid block(int n, Fill fill) {
  Grid g(0.01);
  Pcg32 rng(3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const float v = fill == Fill::Constant ? 0.5F
                        : fill == Fill::Binary ? static_cast<float>((i + j + k) % 2)
                                               : static_cast<float>(rng.uniform());
        g.set_value(i, j, k, v);
      }
    }
  }
  return g;
}

std::vector<char> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::filesystem::path& path, const std::vector<char>& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// Offset of the leaf count of the grid's `__delayedload` metadata: after the type name, the
/// item's byte count (io::DelayedLoadMetadata::readValue reads the count first).
std::size_t delayed_load_count_offset(const std::vector<char>& bytes) {
  constexpr std::string_view type = "__delayedload";
  const std::string_view all(bytes.data(), bytes.size());
  const auto at = all.find(type);
  EXPECT_NE(at, std::string_view::npos);
  return at + type.size() + 4;
}

std::uint32_t read_u32(const std::vector<char>& bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

std::string fill_and_size(const testing::TestParamInfo<std::tuple<int, Fill>>& info) {
  static constexpr const char* fills[] = {"constant", "binary", "random"};
  return fills[static_cast<int>(std::get<1>(info.param))] + std::to_string(std::get<0>(info.param));
}

class GridRoundTrip : public testing::TestWithParam<std::tuple<int, Fill>> {};

TEST_P(GridRoundTrip, GivesBackEveryVoxel) {
  const auto [n, fill] = GetParam();
  const Grid g = block(n, fill);
  const auto path = std::filesystem::temp_directory_path() /
                    ("weft_grid_io_" + std::to_string(n) + "_" + std::to_string(static_cast<int>(fill)) + ".vdb");
  g.save(path);
  // The file lists one mask byte and one size per leaf: (n/8)³ of them, which blosc packs into
  // far fewer bytes for all but random values.
  const auto bytes = read_bytes(path);
  EXPECT_EQ(read_u32(bytes, delayed_load_count_offset(bytes)), static_cast<std::uint32_t>((n / 8) * (n / 8) * (n / 8)));
  const Grid back = Grid::load(path);
  EXPECT_EQ(back.active_voxel_count(), g.active_voxel_count());
  for (int i = 0; i < n; i += 3) {
    for (int j = 0; j < n; j += 5) {
      for (int k = 0; k < n; ++k) ASSERT_EQ(back.value(i, j, k), g.value(i, j, k)) << i << ' ' << j << ' ' << k;
    }
  }
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(SizesAndFills, GridRoundTrip,
                         testing::Combine(testing::Values(64, 128),
                                          testing::Values(Fill::Constant, Fill::Binary, Fill::Random)),
                         fill_and_size);

// OpenVDB's own file writer never checks its stream: a full disk (here a file size limit) must be
// an error naming the file, and the earlier file must stay readable under its name.
TEST(GridSave, ShortWriteIsAnErrorNamingTheFile) {
  const auto path = std::filesystem::temp_directory_path() / "weft_grid_io_short.vdb";
  block(64, Fill::Constant).save(path);
  const auto earlier = read_bytes(path);
  {
    const test::FileSizeLimit limit(earlier.size() + 1024);
    std::string message;
    try {
      block(128, Fill::Random).save(path);
    } catch (const Error& e) {
      message = e.what();
    }
    EXPECT_NE(message.find("cannot write '" + path.string() + "'"), std::string::npos) << message;
  }
  EXPECT_EQ(read_bytes(path), earlier);
  EXPECT_EQ(Grid::load(path).active_voxel_count(), block(64, Fill::Constant).active_voxel_count());
  std::filesystem::remove(path);
}

/// The file of a 64³ checkerboard with its leaf count set to `count`; Grid::load's message.
std::string load_with_leaf_count(std::uint32_t count) {
  const auto path = std::filesystem::temp_directory_path() / ("weft_grid_io_count_" + std::to_string(count) + ".vdb");
  block(64, Fill::Binary).save(path);
  auto bytes = read_bytes(path);
  std::memcpy(bytes.data() + delayed_load_count_offset(bytes), &count, 4);
  write_bytes(path, bytes);
  std::string message;
  try {
    (void)Grid::load(path);
  } catch (const Error& e) {
    message = e.what();
  }
  std::filesystem::remove(path);
  return message;
}

TEST(GridLoad, RefusesALeafCountTheGridCannotHold) {
  // 4 billion leaves (36 GB for readValue to allocate) in a file of a few kilobytes.
  const auto message = load_with_leaf_count(4000000000U);
  EXPECT_NE(message.find("corrupt (grid metadata declares 4000000000 leaves; the "), std::string::npos) << message;
}

TEST(GridLoad, RefusesALeafCountItsArraysDoNotHold) {
  // Within the grid's bytes, but not what the compressed mask array decompresses to.
  const auto message = load_with_leaf_count(513);
  EXPECT_NE(message.find("corrupt (grid metadata: a "), std::string::npos) << message;
  EXPECT_NE(message.find("bytes, expected 513)"), std::string::npos) << message;
}

/// Grid::set_origin's message for `origin` along x (voxels of `h`), "" when it is taken.
std::string origin_error(double origin, double h) {
  Grid g(h);
  try {
    g.set_origin({origin, 0.0, 0.0});
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(GridOrigin, IsRefusedWhereOpenVdbCouldNotCopyTheVoxelSize) {
  // OpenVDB copies a transform (every write, every deepCopy) by recomputing h = (t + h) − t in
  // doubles, t = origin + h/2: 0 once ulp(t) > 2h, i.e. from |t| = 2⁵⁴·h on (ulp(2⁵⁴h) ∈ (2h, 4h]);
  // at 2⁵² h the ulp is at most h, so the recomputed size is at least h/2. Origin 1e20 (h = 0.1)
  // made the save throw "Non-zero scale values required" long after the grid was made.
  for (const double h : {0.1, 0.003, 2.0}) {
    for (const double origin : {0x1p52 * h, -0x1p52 * h}) {
      ASSERT_EQ(origin_error(origin, h), "") << h << ' ' << origin;
      Grid g(h);
      g.set_origin({origin, -origin, 0.5 * origin});
      g.set_value(0, 1, 2, 0.5F);
      g.set_value(3, 1, 2, 0.25F);
      const auto path = std::filesystem::temp_directory_path() / "weft_grid_io_far_origin.vdb";
      g.save(path);
      const Grid back = Grid::load(path);
      EXPECT_EQ(back.voxel_size(), h);
      EXPECT_EQ(back.origin(), g.origin());
      EXPECT_EQ(back.value(3, 1, 2), 0.25F);
      std::filesystem::remove(path);
    }
    for (const double origin : {0x1p54 * h, -0x1p54 * h, 1e20}) {
      const std::string e = origin_error(origin, h);
      EXPECT_NE(e.find("grid 'density': origin ("), std::string::npos) << e;
      EXPECT_NE(e.find(fmt::format("is too far from 0 for voxels of {:g}", h)), std::string::npos) << e;
    }
  }
  EXPECT_NE(origin_error(std::nan(""), 0.1), "");
}

TEST(GridOrigin, ACopyKeepsTheVoxelSizeOpenVdbWouldRound) {
  // At t = 1e15 OpenVDB's own copy (deepCopy, as extinction_grid made it) has voxels of 0.125
  // along x for 0.1: weft's copies share the transform (deep_copy) and keep h and the origin.
  Grid g(0.1);
  g.set_origin({1e15, 1e15, 1e15});
  g.set_value(0, 0, 0, 0.5F);
  ASSERT_EQ(g.impl().grid->deepCopy()->voxelSize()[0], 0.125);  // the rounding avoided
  const Grid mu = extinction_grid(g, 2.0, VoxelRule::linear);
  EXPECT_EQ(mu.voxel_size(), 0.1);
  EXPECT_EQ(mu.origin(), g.origin());
  EXPECT_EQ(mu.value(0, 0, 0), 1.0F);
}

}  // namespace
}  // namespace weft::volume
