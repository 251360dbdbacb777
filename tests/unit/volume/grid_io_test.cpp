// .vdb files through Grid::save and Grid::load, and the pre-check of check_vdb_file
// (docs/robustness.md "Fuzzing", finding 4): valid files of any size and compressibility are read
// back exactly; corrupt counts are still refused before OpenVDB allocates them.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace weft::volume
