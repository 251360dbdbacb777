#include "data_gen/cloth/voxelize.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include <tbb/parallel_for.h>

#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/dist/distributed.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::cloth {
namespace {

constexpr int kLeafLog2 = 3;  // OpenVDB FloatTree leaves are 8³
constexpr int kLeafDim = 1 << kLeafLog2;
constexpr double kPieceVoxels = 4.0;                     // pieces are at most this many voxels long
constexpr std::int64_t kIndexLimit = kMaxVoxelIndex;     // |voxel index| bound that keeps leaf keys in 21 bits
constexpr std::uint64_t kLeafBytes = 512 * 4 + 64 + 96;  // values, mask, node overhead
// A piece is named by one 64-bit id, (point index of its segment's end) << 24 | (run within the
// segment), and rebuilt from the fibres when a leaf needs it: no array of pieces is kept (at
// 72 bytes a piece it was 3× the fibre points themselves, the largest buffer of a run). Run
// indices stay below 2^24 because |voxel index| < 2^22 bounds a segment to < 2^23·√3 voxels,
// so < 2^22 runs of 4 voxels.
constexpr unsigned kRunBits = 24;
constexpr std::uint64_t kRunMask = (1ULL << kRunBits) - 1;
// A bin entry (leaf key, piece id), doubled for the sort's scratch (the scatter's second array),
// plus 2 bytes for its share of the column table (sorted_bins keeps at most one column per 8
// entries, two 8-byte offsets each); every piece has at least one.
constexpr std::uint64_t kBinEntryBytes = 2 * sizeof(std::uint64_t) * 2 + 2;

// A run of quadrature stations of one segment: stations k ∈ [first, last) of `count` spread
// evenly over the whole segment a→b, so station spacing does not depend on how the segment was
// cut into pieces.
struct Piece {
  std::array<double, 3> a;
  std::array<double, 3> b;
  double r;
  std::uint32_t first;
  std::uint32_t last;
  std::uint32_t count;
};

using LeafKey = std::uint64_t;

LeafKey leaf_key(std::int64_t lx, std::int64_t ly, std::int64_t lz) {
  constexpr std::int64_t bias = 1LL << 20;
  return (static_cast<std::uint64_t>(lx + bias) << 42U) | (static_cast<std::uint64_t>(ly + bias) << 21U) |
         static_cast<std::uint64_t>(lz + bias);
}
std::array<int, 3> leaf_origin(LeafKey key) {
  constexpr std::int64_t bias = 1LL << 20;
  const auto unpack = [](std::uint64_t v) { return static_cast<std::int64_t>(v & ((1ULL << 21U) - 1U)) - bias; };
  return {static_cast<int>(unpack(key >> 42U) * kLeafDim), static_cast<int>(unpack(key >> 21U) * kLeafDim),
          static_cast<int>(unpack(key) * kLeafDim)};
}

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// Stations of a segment: at most δ apart (the tiny slack keeps a length that is a whole number
// of δ from gaining a station to rounding).
std::uint64_t station_count(double len, double delta) {
  return static_cast<std::uint64_t>(std::max(1.0, std::ceil(len / delta - 1e-9)));
}

// Stations of segment a→b and how many of them one piece (at most 4 voxels long) holds.
struct SegmentRuns {
  std::uint64_t stations;
  std::uint64_t per_piece;
};
SegmentRuns segment_runs(double len, double h, double delta) {
  const std::uint64_t m = station_count(len, delta);
  return {m, static_cast<std::uint64_t>(std::max(1.0, std::floor(kPieceVoxels * h / (len / m))))};
}

// Calls visit(piece, id) for every piece of every fibre: each segment's stations cut into runs
// spanning at most 4 voxels, in fibre, segment and run order (the order of their ids).
template <typename Visit>
void for_each_piece(const FiberSet& fibers, double h, double delta, Visit visit) {
  for (std::size_t f = 0; f < fibers.size(); ++f) {
    const double r = fibers.radius[f];
    for (std::uint64_t i = fibers.offsets[f] + 1; i < fibers.offsets[f + 1]; ++i) {
      const auto& a = fibers.points[i - 1];
      const auto& b = fibers.points[i];
      const double len = distance(a, b);
      if (!(len > 0.0)) continue;
      const auto [m, per_piece] = segment_runs(len, h, delta);
      if (m > 0xFFFFFFFFULL) fail("fibre {}: a segment of {} mm needs too many quadrature stations", f, len);
      for (std::uint64_t k = 0, run = 0; k < m; k += per_piece, ++run) {
        visit(Piece{a, b, r, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(std::min(m, k + per_piece)),
                    static_cast<std::uint32_t>(m)},
              (i << kRunBits) | run);
      }
    }
  }
}

// The piece of an id from for_each_piece, rebuilt with the same arithmetic.
Piece piece_of(const FiberSet& fibers, std::uint64_t id, double h, double delta) {
  const std::uint64_t i = id >> kRunBits;
  const std::uint64_t run = id & kRunMask;
  // The fibre holding point i: the last offset ≤ i - 1 (segment i - 1 → i lies in one fibre).
  const auto it = std::upper_bound(fibers.offsets.begin(), fibers.offsets.end(), i - 1);
  const auto f = static_cast<std::size_t>(it - fibers.offsets.begin() - 1);
  const auto& a = fibers.points[i - 1];
  const auto& b = fibers.points[i];
  const auto [m, per_piece] = segment_runs(distance(a, b), h, delta);
  const std::uint64_t k = run * per_piece;
  return Piece{a,
               b,
               fibers.radius[f],
               static_cast<std::uint32_t>(k),
               static_cast<std::uint32_t>(std::min(m, k + per_piece)),
               static_cast<std::uint32_t>(m)};
}

// Leaf-coordinate box of a piece's bounding box grown by its radius (and a hair more, so a
// quadrature point rounded across the box edge still finds its leaf in the bin).
std::array<std::int64_t, 6> leaf_box(const Piece& p, double h) {
  std::array<std::int64_t, 6> box{};
  const double pad = p.r + 1e-9 * h;
  const double t0 = static_cast<double>(p.first) / p.count;
  const double t1 = static_cast<double>(p.last) / p.count;
  for (int c = 0; c < 3; ++c) {
    const double e0 = p.a[c] + (p.b[c] - p.a[c]) * t0;
    const double e1 = p.a[c] + (p.b[c] - p.a[c]) * t1;
    const double lo = std::min(e0, e1) - pad;
    const double hi = std::max(e0, e1) + pad;
    box[c] = static_cast<std::int64_t>(std::floor(lo / h)) >> kLeafLog2;
    box[c + 3] = static_cast<std::int64_t>(std::floor(hi / h)) >> kLeafLog2;
  }
  return box;
}

// Calls deposit(x, y, z, weight) for each quadrature point of the cylinder piece: stations at
// slice midpoints along the axis; on each, a disc of points ~δ apart; each point weighs its
// share of the slice volume, so the weights sum to length·πr² exactly.
// Stations whose disc cannot reach the world box [lo, hi] are skipped (their points would land in
// another leaf, which deposits them itself).
template <typename Deposit>
void quadrature(const Piece& p, double delta, const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                Deposit deposit) {
  std::array<double, 3> d{p.b[0] - p.a[0], p.b[1] - p.a[1], p.b[2] - p.a[2]};
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (double& v : d) v /= len;
  // Orthonormal basis around d (Duff et al. 2017, "Building an orthonormal basis, revisited").
  const double sign = std::copysign(1.0, d[2]);
  const double a = -1.0 / (sign + d[2]);
  const double bb = d[0] * d[1] * a;
  const std::array<double, 3> u{1.0 + sign * d[0] * d[0] * a, sign * bb, -sign * d[0]};
  const std::array<double, 3> v{bb, sign + d[1] * d[1] * a, -d[1]};
  const double stations = p.count;
  // Sunflower (Vogel spiral) disc: point i at radius r·√((i+½)/N), angle i·golden. Every point
  // stands for the same area πr²/N and their local density is nearly uniform, which keeps a
  // voxel's share close to its true overlap (a voxel fully inside a fibre gets C ≈ 1, not a
  // noisy value that clamping would eat).
  const auto disc =
      static_cast<std::uint32_t>(std::max(1.0, std::ceil(std::numbers::pi * p.r * p.r / (delta * delta) - 1e-9)));
  const double w = len / stations * std::numbers::pi * p.r * p.r / disc;
  constexpr double golden = 2.399963229728653;  // golden angle
  // The disc in its own plane, once per piece; stations only rotate it (no trig per point).
  thread_local std::vector<std::array<double, 2>> pattern;
  pattern.resize(disc);
  for (std::uint32_t i = 0; i < disc; ++i) {
    const double rho = p.r * std::sqrt((i + 0.5) / disc);
    pattern[i] = {rho * std::cos(golden * i), rho * std::sin(golden * i)};
  }
  for (std::uint32_t s = p.first; s < p.last; ++s) {
    const double t = (s + 0.5) / stations * len;
    const std::array<double, 3> c{p.a[0] + d[0] * t, p.a[1] + d[1] * t, p.a[2] + d[2] * t};
    const double reach = p.r * (1.0 + 1e-9) + 1e-12;
    if (c[0] + reach < lo[0] || c[0] - reach > hi[0] || c[1] + reach < lo[1] || c[1] - reach > hi[1] ||
        c[2] + reach < lo[2] || c[2] - reach > hi[2]) {
      continue;
    }
    // Turn successive stations by an irrational fraction of a turn so their points interleave.
    const double phase = 2.0 * std::numbers::pi * std::fmod(0.7548776662466927 * s, 1.0);
    const double cp = std::cos(phase);
    const double sp = std::sin(phase);
    const std::array<double, 3> ru{cp * u[0] + sp * v[0], cp * u[1] + sp * v[1], cp * u[2] + sp * v[2]};
    const std::array<double, 3> rv{cp * v[0] - sp * u[0], cp * v[1] - sp * u[1], cp * v[2] - sp * u[2]};
    for (const auto& [x, y] : pattern) {
      deposit(c[0] + x * ru[0] + y * rv[0], c[1] + x * ru[1] + y * rv[1], c[2] + x * ru[2] + y * rv[2], w);
    }
  }
}

void check_options(const VoxelizeOptions& o) {
  require_positive("voxel_size", o.voxel_size);
  if (o.samples_per_voxel < 1 || o.samples_per_voxel > 64) {
    fail("samples_per_voxel must be in [1, 64], got {}", o.samples_per_voxel);
  }
}

// The option that sets the budget, as the asker writes it (docs/python.md "One set of checks").
const std::string& budget_option(const VoxelizeOptions& o) {
  static const Spelling option{"--max-memory", "max_memory_mb="};
  return option.in(o.asker);
}

}  // namespace

VoxelizeEstimate estimate_voxelize_memory(const FiberSet& fibers, const VoxelizeOptions& options) {
  check_options(options);
  const double h = options.voxel_size;
  VoxelizeEstimate e;
  // Cheap bounds first (O(segments)): the index range and the piece count, so an absurd voxel
  // size is refused before the per-piece pass could take long.
  std::array<double, 3> lo{1e300, 1e300, 1e300};
  std::array<double, 3> hi{-1e300, -1e300, -1e300};
  double max_r = 0.0;
  double pieces = 0.0;
  for (std::size_t f = 0; f < fibers.size(); ++f) {
    const double r = fibers.radius[f];
    if (!(r > 0.0) || !std::isfinite(r)) fail("fibre {}: radius must be finite and > 0, got {}", f, r);
    max_r = std::max(max_r, r);
    for (std::uint64_t i = fibers.offsets[f]; i < fibers.offsets[f + 1]; ++i) {
      const auto& p = fibers.points[i];
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(p[c])) fail("fibre {}: point {} is not finite", f, i - fibers.offsets[f]);
        lo[c] = std::min(lo[c], p[c]);
        hi[c] = std::max(hi[c], p[c]);
      }
      if (i > fibers.offsets[f])
        pieces += std::max(1.0, std::ceil(distance(fibers.points[i - 1], p) / (kPieceVoxels * h)));
    }
  }
  for (int c = 0; c < 3; ++c) {
    const double a = std::floor((lo[c] - max_r) / h);
    const double b = std::floor((hi[c] + max_r) / h);
    if (std::abs(a) >= static_cast<double>(kIndexLimit) || std::abs(b) >= static_cast<double>(kIndexLimit)) {
      fail("voxel_size {} mm: the fibres span voxel indices beyond ±{} on axis {}; use a larger voxel size", h,
           kIndexLimit, "xyz"[c]);
    }
  }
  const std::uint64_t budget = options.max_memory_bytes > 0 ? options.max_memory_bytes : default_memory_budget();
  if (pieces * static_cast<double>(kBinEntryBytes) > static_cast<double>(budget)) {
    fail("voxel_size {} mm: {:.3g} fibre pieces alone would exceed the memory budget of {} ({})", h, pieces,
         format_bytes(budget), budget_option(options));
  }
  e.pieces = 0;
  for_each_piece(fibers, h, h / options.samples_per_voxel, [&](const Piece& p, std::uint64_t /*id*/) {
    ++e.pieces;
    const auto box = leaf_box(p, h);
    e.bin_entries += static_cast<std::uint64_t>((box[3] - box[0] + 1) * (box[4] - box[1] + 1) * (box[5] - box[2] + 1));
  });
  double box_leaves = 1.0;
  for (int c = 0; c < 3; ++c) {
    box_leaves *= std::floor(std::floor((hi[c] + max_r) / h) / kLeafDim) -
                  std::floor(std::floor((lo[c] - max_r) / h) / kLeafDim) + 1.0;
  }
  e.leaves = static_cast<std::uint64_t>(std::min(static_cast<double>(e.bin_entries), box_leaves));
  // Bins (with the sort's scratch), leaves twice (built, then moved into the tree).
  e.bytes = e.bin_entries * kBinEntryBytes + e.leaves * kLeafBytes * 2;
  return e;
}

namespace {

using Bin = std::pair<LeafKey, std::uint64_t>;

// Bins pieces by leaf: the (leaf key, piece id) pairs in increasing order, so each leaf sees its
// pieces in id order (fibre, segment, run) whatever the thread count. The pairs are scattered
// into columns of leaves (the key's x and y, its bits above 21; slabs of x where the columns'
// box would be too large to count), each column a contiguous range of increasing keys, then each
// column sorted on its own: the same order as one sort of all the pairs, with the columns as the
// units of a parallel loop that reports as it goes, so the binning stops within a column's time
// on Ctrl-C instead of after the whole sort. The scatter's second array is the scratch that
// kBinEntryBytes counts.
std::vector<Bin> sorted_bins(const FiberSet& fibers, double h, double delta, std::uint64_t entries,
                             ProgressSink& progress) {
  std::vector<Bin> bins;
  bins.reserve(entries);
  {
    ProgressTask task(progress, "binning fibre pieces", entries);
    constexpr std::size_t kReportEvery = std::size_t{1} << 20U;
    std::size_t reported = 0;
    for_each_piece(fibers, h, delta, [&](const Piece& p, std::uint64_t id) {
      const auto box = leaf_box(p, h);
      for (std::int64_t x = box[0]; x <= box[3]; ++x) {
        for (std::int64_t y = box[1]; y <= box[4]; ++y) {
          for (std::int64_t z = box[2]; z <= box[5]; ++z) bins.emplace_back(leaf_key(x, y, z), id);
        }
      }
      if (bins.size() - reported >= kReportEvery) {
        task.step(bins.size() - reported);
        reported = bins.size();
      }
    });
    task.step(bins.size() - reported);
  }
  if (bins.empty()) return bins;
  // Column of a key: (x, y) in leaves, numbered x-major over the box the keys span, so column
  // order is key order; x slabs alone when that box would pass kMaxColumns.
  constexpr std::uint64_t kField = (1ULL << 21U) - 1;
  constexpr std::uint64_t kMaxColumns = 1ULL << 22U;
  std::uint64_t x_lo = kField;
  std::uint64_t x_hi = 0;
  std::uint64_t y_lo = kField;
  std::uint64_t y_hi = 0;
  for (const Bin& b : bins) {
    const std::uint64_t x = b.first >> 42U;
    const std::uint64_t y = (b.first >> 21U) & kField;
    x_lo = std::min(x_lo, x);
    x_hi = std::max(x_hi, x);
    y_lo = std::min(y_lo, y);
    y_hi = std::max(y_hi, y);
  }
  // At most one column per 8 entries (the table kBinEntryBytes counts): columns of (x, y), else
  // slabs of x, else one sort of everything (few entries spread over a wide box: a short sort).
  const std::uint64_t table_limit = std::min<std::uint64_t>(kMaxColumns, bins.size() / 8 + 1);
  const std::uint64_t nx = x_hi - x_lo + 1;
  const bool by_column = nx * (y_hi - y_lo + 1) <= table_limit;
  const bool by_slab = !by_column && nx <= table_limit;
  const std::uint64_t ny = by_column ? y_hi - y_lo + 1 : 1;
  const auto column = [&](LeafKey k) -> std::size_t {
    if (!by_column && !by_slab) return 0;
    const std::uint64_t x = (k >> 42U) - x_lo;
    return by_column ? x * ny + (((k >> 21U) & kField) - y_lo) : x;
  };
  const std::size_t columns = by_column || by_slab ? nx * ny : 1;
  std::vector<std::size_t> start(columns + 1, 0);
  for (const Bin& b : bins) ++start[column(b.first) + 1];
  for (std::size_t c = 0; c < columns; ++c) start[c + 1] += start[c];
  std::vector<Bin> sorted(bins.size());
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (const Bin& b : bins) sorted[next[column(b.first)]++] = b;
  }
  bins = std::vector<Bin>();
  ProgressTask task(progress, "sorting fibre pieces by leaf", columns);
  parallel_units(columns, [&](std::size_t c) {
    std::sort(sorted.begin() + static_cast<std::ptrdiff_t>(start[c]),
              sorted.begin() + static_cast<std::ptrdiff_t>(start[c + 1]));
    task.step();
  });
  return sorted;
}

}  // namespace

volume::Grid voxelize(const FiberSet& fibers, const VoxelizeOptions& options, VoxelizeReport& report,
                      ProgressSink& progress) {
  const auto start = std::chrono::steady_clock::now();
  check_options(options);
  if (fibers.size() == 0) fail("voxelize: there are no fibres");
  const double h = options.voxel_size;
  const VoxelizeEstimate estimate = estimate_voxelize_memory(fibers, options);
  const std::uint64_t budget = options.max_memory_bytes > 0 ? options.max_memory_bytes : default_memory_budget();
  // Two checks: the pieces and bins (exact counts) before they are made, then the leaves once
  // the sorted bins say how many there are (the bound from the bounding box alone refused
  // long yarns meandering through a large, mostly empty box).
  const std::uint64_t binning = estimate.bin_entries * kBinEntryBytes;
  if (binning > budget) {
    const auto [need, limit] = format_bytes_apart(binning, budget);
    fail("voxel_size {} mm: voxelizing would take {} for {} fibre pieces alone, over the memory budget of {} ({})", h,
         need, estimate.pieces, limit, budget_option(options));
  }

  const double delta = h / options.samples_per_voxel;
  const std::vector<Bin> bins = sorted_bins(fibers, h, delta, estimate.bin_entries, progress);
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    if (i == 0 || bins[i].first != bins[i - 1].first) starts.push_back(i);
  }
  starts.push_back(bins.size());
  const std::size_t leaf_count = starts.size() - 1;
  if (binning + leaf_count * kLeafBytes > budget) {
    const auto [need, limit] = format_bytes_apart(binning + leaf_count * kLeafBytes, budget);
    fail(
        "voxel_size {} mm: voxelizing would take up to {} ({} leaves of 8^3 voxels), over the memory budget of {} "
        "({})",
        h, need, leaf_count, limit, budget_option(options));
  }

  using Leaf = openvdb::FloatTree::LeafNodeType;
  std::vector<Leaf*> leaves(leaf_count, nullptr);
  std::vector<double> kept(leaf_count, 0.0);
  std::vector<double> lost(leaf_count, 0.0);
  const double inv_volume = 1.0 / (h * h * h);
  const double inv_h = 1.0 / h;
  // Leaf l from its bin: the pieces in index order, so its values do not depend on who fills it.
  const auto fill_leaf = [&](std::size_t l, std::array<double, 512>& acc) {
    acc.fill(0.0);
    const auto origin = leaf_origin(bins[starts[l]].first);
    // World box of the leaf, padded by a hundredth of a voxel against rounding.
    const std::array<double, 3> lo{(origin[0] - 0.01) * h, (origin[1] - 0.01) * h, (origin[2] - 0.01) * h};
    const std::array<double, 3> hi{(origin[0] + kLeafDim + 0.01) * h, (origin[1] + kLeafDim + 0.01) * h,
                                   (origin[2] + kLeafDim + 0.01) * h};
    bool any = false;
    for (std::size_t e = starts[l]; e < starts[l + 1]; ++e) {
      quadrature(piece_of(fibers, bins[e].second, h, delta), delta, lo, hi,
                 [&](double x, double y, double z, double w) {
                   const auto i = static_cast<std::int64_t>(std::floor(x * inv_h)) - origin[0];
                   const auto j = static_cast<std::int64_t>(std::floor(y * inv_h)) - origin[1];
                   const auto k = static_cast<std::int64_t>(std::floor(z * inv_h)) - origin[2];
                   if (i < 0 || j < 0 || k < 0 || i >= kLeafDim || j >= kLeafDim || k >= kLeafDim) return;
                   acc[static_cast<std::size_t>((i << 6) | (j << 3) | k)] += w;
                   any = true;
                 });
    }
    if (!any) return;
    auto* leaf = new Leaf(openvdb::Coord(origin[0], origin[1], origin[2]), 0.0f, false);
    double kept_volume = 0.0;
    double lost_volume = 0.0;
    for (std::size_t n = 0; n < acc.size(); ++n) {
      if (acc[n] <= 0.0) continue;
      const double c = acc[n] * inv_volume;
      const float stored = static_cast<float>(std::min(c, 1.0));
      leaf->setValueOn(static_cast<openvdb::Index>(n), stored);
      kept_volume += static_cast<double>(stored);
      if (c > 1.0) lost_volume += (c - 1.0) / inv_volume;
    }
    leaves[l] = leaf;
    kept[l] = kept_volume / inv_volume;
    lost[l] = lost_volume;
  };
  if (options.spread && dist::size() > 1) {
    // Under mpirun (weft gen): units = ranges of leaves over the ranks (dist::run_units). A leaf
    // crosses as its flag, kept and lost volumes, active mask and 512 values (≈ 2.1 kB, the size
    // of the grid itself); rank 0 rebuilds the same leaves, so the grid and the report are the
    // bytes of one process. Fibres, pieces and bins are made on every rank (the serial part).
    constexpr std::size_t kLeavesPerUnit = 256;
    const std::size_t units = (leaf_count + kLeavesPerUnit - 1) / kLeavesPerUnit;
    ProgressTask task(progress, "voxelizing (leaf ranges)", units);
    dist::UnitsOptions how;
    how.progress = &task;
    how.name = [&](std::size_t u) {
      return fmt::format("voxelizer leaves {}..{}", u * kLeavesPerUnit,
                         std::min(leaf_count, (u + 1) * kLeavesPerUnit) - 1);
    };
    using Word = openvdb::util::NodeMask<kLeafLog2>::Word;
    constexpr std::size_t kWords = openvdb::util::NodeMask<kLeafLog2>::WORD_COUNT;
    const std::vector<dist::Bytes> results = dist::run_units(
        units,
        [&](std::size_t u) {
          dist::Bytes b;
          std::array<double, 512> acc{};
          const auto put = [&b](const void* data, std::size_t n) {
            const auto* p = static_cast<const std::uint8_t*>(data);
            b.insert(b.end(), p, p + n);
          };
          for (std::size_t l = u * kLeavesPerUnit; l < std::min(leaf_count, (u + 1) * kLeavesPerUnit); ++l) {
            fill_leaf(l, acc);
            const std::uint8_t has = leaves[l] != nullptr ? 1 : 0;
            put(&has, 1);
            if (has == 0) continue;
            put(&kept[l], sizeof(double));
            put(&lost[l], sizeof(double));
            for (std::size_t w = 0; w < kWords; ++w) {
              const Word word = leaves[l]->getValueMask().getWord<Word>(static_cast<openvdb::Index>(w));
              put(&word, sizeof word);
            }
            put(leaves[l]->buffer().data(), 512 * sizeof(float));
            delete leaves[l];  // rank 0 rebuilds it from the bytes, as from any rank
            leaves[l] = nullptr;
          }
          return b;
        },
        how);
    if (dist::is_root()) {
      for (std::size_t u = 0; u < results.size(); ++u) {
        const dist::Bytes& b = results[u];
        std::size_t at = 0;
        const auto get = [&](void* data, std::size_t n) {
          if (at + n > b.size()) fail("voxelize: a truncated leaf range from another rank");
          std::memcpy(data, b.data() + at, n);
          at += n;
        };
        for (std::size_t l = u * kLeavesPerUnit; l < std::min(leaf_count, (u + 1) * kLeavesPerUnit); ++l) {
          std::uint8_t has = 0;
          get(&has, 1);
          if (has == 0) continue;
          get(&kept[l], sizeof(double));
          get(&lost[l], sizeof(double));
          const auto origin = leaf_origin(bins[starts[l]].first);
          auto* leaf = new Leaf(openvdb::Coord(origin[0], origin[1], origin[2]), 0.0f, false);
          std::array<Word, kWords> words{};
          get(words.data(), sizeof words);
          std::array<float, 512> values{};
          get(values.data(), sizeof values);
          for (std::size_t n = 0; n < 512; ++n) {
            if (((words[n / 64] >> (n % 64)) & 1U) != 0) leaf->setValueOn(static_cast<openvdb::Index>(n), values[n]);
          }
          leaves[l] = leaf;
        }
      }
    }
  } else {
    ProgressTask task(progress, "voxelizing", leaf_count);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaf_count, 16),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        std::array<double, 512> acc{};
                        for (std::size_t l = range.begin(); l != range.end(); ++l) {
                          fill_leaf(l, acc);
                          task.step();
                        }
                      });
  }

  volume::Grid grid(h, "density");
  grid.set_origin({0.0, 0.0, 0.0});
  auto& tree = grid.impl().grid->tree();
  double grid_volume = 0.0;
  double lost_volume = 0.0;
  for (std::size_t l = 0; l < leaf_count; ++l) {
    grid_volume += kept[l];
    lost_volume += lost[l];
    if (leaves[l] != nullptr) tree.addLeaf(leaves[l]);  // the tree takes ownership
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.fiber_volume = fibers.volume();
  report.grid_volume = grid_volume;
  report.relative_error = report.fiber_volume > 0.0 ? (grid_volume - report.fiber_volume) / report.fiber_volume : 0.0;
  report.overlap_fraction = report.fiber_volume > 0.0 ? lost_volume / report.fiber_volume : 0.0;
  report.active_voxels = grid.active_voxel_count();
  report.fiber_count = fibers.size();
  report.voxelize_seconds = seconds;
  grid.set_metadata("units", "mm");
  grid.set_metadata("value_kind", "concentration");
  grid.set_metadata("voxel_size", fmt::format("{}", h));
  return grid;
}

}  // namespace weft::cloth
