// Window-mean concentration statistics from one streaming pass over the columns.
#include "weft/fit/window_stats.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/fit/moments.h"
#include "weft/volume/columns.h"

namespace weft::fit {
namespace {

constexpr std::size_t kShards = 64;  // fixed: results do not depend on the thread count

}  // namespace

int window_voxels(double window, double h, int n) {
  if (!(window > 0.0)) return n;
  return static_cast<int>(std::clamp<double>(std::round(window / h), 1.0, static_cast<double>(n)));
}

ConcentrationStats window_stats(const volume::Grid& grid, int axis, double window, ProgressSink& progress) {
  if (axis < 0 || axis > 2) fail("window statistics: axis must be 0, 1 or 2, got {}", axis);
  if (!std::isfinite(window) || !(window >= 0.0)) fail("window statistics: window must be >= 0, got {}", window);
  if (grid.active_voxel_count() == 0) fail("window statistics: grid '{}' has no active voxels", grid.name());
  const volume::ColumnReader reader(grid, axis);
  const int n = static_cast<int>(reader.box().extent()[axis]);
  const double h = grid.voxel_size();
  const int w = window_voxels(window, h, n);
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  std::vector<Moments> parts(shards);
  // Direct sums keep identical windows bit-identical (so a uniform medium has Var C = 0
  // exactly); prefix sums are used only where direct sums would cost more than 16 passes.
  const int positions = n - w + 1;
  const bool direct = static_cast<long long>(positions) * w <= 16LL * n;
  ProgressTask task(progress, fmt::format("window statistics {}", "xyz"[axis]), units);
  parallel_units(shards, [&](std::size_t shard) {
    volume::ColumnTile tile;
    std::vector<double> prefix(static_cast<std::size_t>(n) + 1);
    for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
      reader.read(unit, tile);
      for (int iu = 0; iu < tile.nu; ++iu) {
        for (int iv = 0; iv < tile.nv; ++iv) {
          const float* col = tile.column(iu, iv);
          if (direct) {
            for (int s = 0; s < positions; ++s) {
              double sum = 0.0;
              for (int k = s; k < s + w; ++k) sum += static_cast<double>(col[k]);
              parts[shard].add(sum / w);
            }
          } else {
            prefix[0] = 0.0;
            for (int k = 0; k < n; ++k)
              prefix[static_cast<std::size_t>(k) + 1] = prefix[static_cast<std::size_t>(k)] + col[k];
            for (int s = 0; s < positions; ++s) {
              parts[shard].add((prefix[static_cast<std::size_t>(s + w)] - prefix[static_cast<std::size_t>(s)]) / w);
            }
          }
        }
      }
      task.step();
    }
  });
  Moments total;
  for (const auto& p : parts) total.merge(p);
  ConcentrationStats out;
  out.mean = total.mean;
  out.variance = total.variance();
  out.samples = total.n;
  out.window_voxels = w;
  out.window = w * h;
  return out;
}

}  // namespace weft::fit
