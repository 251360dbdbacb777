// Local gamma statistics per block of B³ voxels, as coarse grids for rendering (design §3).
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "weft/core/error.h"
#include "weft/core/floor_div.h"
#include "weft/core/parallel.h"
#include "weft/fit/fit.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::fit {
namespace {

struct BlockResult {
  std::array<std::int64_t, 3> key{};
  double mean = 0.0;
  std::array<double, 3> variance{};
};

}  // namespace

LocalFields local_fields(const volume::Grid& grid, int block, ProgressSink& progress) {
  if (block < 1 || block > 4096) fail("local fields: block size must be in 1..4096 voxels, got {}", block);
  if (grid.active_voxel_count() == 0) fail("local fields: grid '{}' has no active voxels", grid.name());
  const auto& vdb = *grid.impl().grid;
  std::set<std::array<std::int64_t, 3>> keys;
  for (auto it = vdb.cbeginValueOn(); it; ++it) {
    if (!(*it > 0.0f)) continue;
    openvdb::CoordBBox b;
    it.getBoundingBox(b);
    for (std::int64_t i = floor_div(b.min().x(), block); i <= floor_div(b.max().x(), block); ++i) {
      for (std::int64_t j = floor_div(b.min().y(), block); j <= floor_div(b.max().y(), block); ++j) {
        for (std::int64_t k = floor_div(b.min().z(), block); k <= floor_div(b.max().z(), block); ++k)
          keys.insert({i, j, k});
      }
    }
  }
  const std::vector<std::array<std::int64_t, 3>> list(keys.begin(), keys.end());
  std::vector<BlockResult> results(list.size());
  const auto B = static_cast<std::size_t>(block);
  ProgressTask task(progress, "local fields", list.size());
  parallel_units(list.size(), [&](std::size_t u) {
    auto acc = vdb.getConstAccessor();
    std::vector<double> dense(B * B * B);
    const auto& key = list[u];
    double total = 0.0;
    for (std::size_t i = 0; i < B; ++i) {
      for (std::size_t j = 0; j < B; ++j) {
        for (std::size_t k = 0; k < B; ++k) {
          const openvdb::Coord c(static_cast<int>(key[0] * block + static_cast<std::int64_t>(i)),
                                 static_cast<int>(key[1] * block + static_cast<std::int64_t>(j)),
                                 static_cast<int>(key[2] * block + static_cast<std::int64_t>(k)));
          float v = 0.0f;
          if (!acc.probeValue(c, v)) v = 0.0f;
          dense[(i * B + j) * B + k] = v;
          total += v;
        }
      }
    }
    BlockResult r;
    r.key = key;
    r.mean = total / static_cast<double>(B * B * B);
    // Per axis: the B² column means across the block (the block is the window, Eq. 19).
    for (int axis = 0; axis < 3; ++axis) {
      double sum = 0.0;
      double sum2 = 0.0;
      for (std::size_t p = 0; p < B; ++p) {
        for (std::size_t q = 0; q < B; ++q) {
          double col = 0.0;
          for (std::size_t s = 0; s < B; ++s) {
            const std::size_t i = axis == 0 ? s : p;
            const std::size_t j = axis == 1 ? s : (axis == 0 ? p : q);
            const std::size_t k = axis == 2 ? s : q;
            col += dense[(i * B + j) * B + k];
          }
          col /= static_cast<double>(B);
          sum += col - r.mean;
          sum2 += (col - r.mean) * (col - r.mean);
        }
      }
      const auto m = static_cast<double>(B * B);
      r.variance[static_cast<std::size_t>(axis)] = std::max(0.0, sum2 / m - (sum / m) * (sum / m));
    }
    results[u] = r;
    task.step();
  });

  LocalFields out;
  out.block = block;
  const double coarse = grid.voxel_size() * block;
  const auto origin = grid.origin();
  auto make = [&](const std::string& name) {
    volume::Grid g(coarse, name);
    g.set_origin(origin);
    for (const auto& [k, v] : grid.metadata()) {
      if (k.rfind("weft:", 0) == 0) g.set_metadata(k, v);
    }
    g.set_metadata("weft:local_block_voxels", std::to_string(block));
    return g;
  };
  out.mean = make("mean_concentration");
  for (int a = 0; a < 3; ++a) {
    const char axis = "xyz"[a];
    out.variance[static_cast<std::size_t>(a)] = make(fmt::format("var_concentration_{}", axis));
    out.alpha[static_cast<std::size_t>(a)] = make(fmt::format("alpha_{}", axis));
    out.beta[static_cast<std::size_t>(a)] = make(fmt::format("beta_{}", axis));
  }
  constexpr float inf = std::numeric_limits<float>::infinity();
  for (const auto& r : results) {
    if (!(r.mean > 0.0)) continue;
    const int i = static_cast<int>(r.key[0]);
    const int j = static_cast<int>(r.key[1]);
    const int k = static_cast<int>(r.key[2]);
    out.mean.set_value(i, j, k, static_cast<float>(r.mean));
    for (std::size_t a = 0; a < 3; ++a) {
      const double var = r.variance[a];
      out.variance[a].set_value(i, j, k, static_cast<float>(var));
      out.alpha[a].set_value(i, j, k, var > 0.0 ? static_cast<float>(r.mean * r.mean / var) : inf);
      out.beta[a].set_value(i, j, k, var > 0.0 ? static_cast<float>(r.mean / var) : inf);
    }
    ++out.blocks;
  }
  return out;
}

void save_local_fields(const LocalFields& f, const std::filesystem::path& path) {
  std::vector<volume::Grid> grids{f.mean};
  for (std::size_t a = 0; a < 3; ++a) grids.push_back(f.variance[a]);
  for (std::size_t a = 0; a < 3; ++a) grids.push_back(f.alpha[a]);
  for (std::size_t a = 0; a < 3; ++a) grids.push_back(f.beta[a]);
  volume::save_grids(grids, path);
}

}  // namespace weft::fit
