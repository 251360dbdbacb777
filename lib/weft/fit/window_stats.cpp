// Window-mean concentration statistics from one streaming pass over the columns.
#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/fit/fit.h"
#include "weft/volume/columns.h"

namespace weft::fit {
namespace {

constexpr std::size_t kShards = 64;  // fixed: results do not depend on the thread count

/// Welford running moments; Chan et al.'s pairwise merge, in shard order.
struct Moments {
  std::uint64_t n = 0;
  double mean = 0.0;
  double m2 = 0.0;
  void add(double x) {
    ++n;
    const double delta = x - mean;
    mean += delta / static_cast<double>(n);
    m2 += delta * (x - mean);
  }
  void merge(const Moments& o) {
    if (o.n == 0) return;
    if (n == 0) {
      *this = o;
      return;
    }
    const double na = static_cast<double>(n);
    const double nb = static_cast<double>(o.n);
    const double delta = o.mean - mean;
    const double total = na + nb;
    mean += delta * nb / total;
    m2 += o.m2 + delta * delta * na * nb / total;
    n += o.n;
  }
};

}  // namespace

ConcentrationStats window_stats(const volume::Grid& grid, int axis, double window, ProgressSink& progress) {
  if (axis < 0 || axis > 2) fail("window statistics: axis must be 0, 1 or 2, got {}", axis);
  if (!std::isfinite(window) || !(window >= 0.0)) fail("window statistics: window must be >= 0, got {}", window);
  if (grid.active_voxel_count() == 0) fail("window statistics: grid '{}' has no active voxels", grid.name());
  const volume::ColumnReader reader(grid, axis);
  const int n = static_cast<int>(reader.box().extent()[axis]);
  const double h = grid.voxel_size();
  int w = n;
  if (window > 0.0) w = static_cast<int>(std::clamp<double>(std::round(window / h), 1.0, static_cast<double>(n)));
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
  out.variance = total.n > 0 ? std::max(0.0, total.m2 / static_cast<double>(total.n)) : 0.0;
  out.samples = total.n;
  out.window_voxels = w;
  out.window = w * h;
  return out;
}

double correlation_length(const volume::Grid& grid, int axis, ProgressSink& progress) {
  if (axis < 0 || axis > 2) fail("correlation length: axis must be 0, 1 or 2, got {}", axis);
  if (grid.active_voxel_count() == 0) fail("correlation length: grid '{}' has no active voxels", grid.name());
  const volume::ColumnReader reader(grid, axis);
  const auto ext = reader.box().extent();
  const int n = static_cast<int>(ext[axis]);
  const double h = grid.voxel_size();
  const int max_lag = std::min(n - 1, 128);
  if (max_lag < 1) return n * h;
  const double mean =
      grid.sum() / (static_cast<double>(ext[0]) * static_cast<double>(ext[1]) * static_cast<double>(ext[2]));
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  const auto lags = static_cast<std::size_t>(max_lag) + 1;
  // Autocovariance at lags [l0, l1), one streaming pass; summed per shard, merged in order.
  auto covariance = [&](std::size_t l0, std::size_t l1) {
    std::vector<std::vector<double>> parts(shards, std::vector<double>(l1 - l0, 0.0));
    ProgressTask task(progress, fmt::format("correlation length {}", "xyz"[axis]), units);
    parallel_units(shards, [&](std::size_t shard) {
      volume::ColumnTile tile;
      std::vector<double> dev(static_cast<std::size_t>(n));
      auto& acc = parts[shard];
      for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
        reader.read(unit, tile);
        for (int iu = 0; iu < tile.nu; ++iu) {
          for (int iv = 0; iv < tile.nv; ++iv) {
            const float* col = tile.column(iu, iv);
            for (int k = 0; k < n; ++k) dev[static_cast<std::size_t>(k)] = static_cast<double>(col[k]) - mean;
            for (std::size_t l = l0; l < l1; ++l) {
              double s = 0.0;
              for (std::size_t k = 0; k + l < static_cast<std::size_t>(n); ++k) s += dev[k] * dev[k + l];
              acc[l - l0] += s;
            }
          }
        }
        task.step();
      }
    });
    std::vector<double> cov(l1 - l0, 0.0);
    for (const auto& p : parts) {
      for (std::size_t l = l0; l < l1; ++l) cov[l - l0] += p[l - l0];
    }
    // Per pair of voxels at lag l (n − l pairs per column).
    for (std::size_t l = l0; l < l1; ++l) cov[l - l0] /= static_cast<double>(n - static_cast<int>(l));
    return cov;
  };
  // Lags in growing blocks (up to 8, 32, 128): most media decorrelate within the first.
  std::vector<double> cov;
  const double threshold = std::exp(-1.0);
  double prev = 1.0;
  std::size_t next = 0;
  for (std::size_t end : {std::size_t{9}, std::size_t{33}, lags}) {
    end = std::min(end, lags);
    if (end <= next) continue;
    const auto block = covariance(next, end);
    cov.insert(cov.end(), block.begin(), block.end());
    if (!(cov[0] > 0.0)) return n * h;
    for (std::size_t l = std::max<std::size_t>(next, 1); l < end; ++l) {
      const double r = cov[l] / cov[0];
      if (r <= threshold) {
        const double frac = (prev - threshold) / (prev - r);
        return (static_cast<double>(l) - 1.0 + frac) * h;
      }
      prev = r;
    }
    next = end;
  }
  return n * h;
}

}  // namespace weft::fit
