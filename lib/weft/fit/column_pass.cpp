// The predictive models' one sparse pass over an axis beam's columns (fit/column_pass.h).
#include "weft/fit/column_pass.h"

#include <algorithm>
#include <array>

#include "weft/core/error.h"
#include "weft/core/parallel.h"

namespace weft::fit::detail {
namespace {

/// A shard's block sums, kept only for the coarse columns its patches touch (a shard is a run of
/// neighbouring patches), so memory follows the face, not shards × blocks.
struct ShardBlocks {
  std::vector<std::int32_t> slot;  ///< per coarse column: its place below, or −1
  std::vector<std::size_t> touched;
  std::vector<Sums> sums;     ///< [place·nb + b]: s and s2 of the closed columns' block means
  std::vector<double> cross;  ///< [place·nb + b]: Σ mean_b · mean_b+1
  std::vector<double> rays;   ///< per place: beam columns
  std::vector<double> open;   ///< per place: columns empty over the whole depth
  std::vector<double> closed;

  std::size_t place(std::size_t coarse, std::int64_t nb) {
    if (slot[coarse] < 0) {
      slot[coarse] = static_cast<std::int32_t>(touched.size());
      touched.push_back(coarse);
      sums.resize(sums.size() + static_cast<std::size_t>(nb));
      cross.resize(cross.size() + static_cast<std::size_t>(nb), 0.0);
      rays.push_back(0.0);
      open.push_back(0.0);
      closed.push_back(0.0);
    }
    return static_cast<std::size_t>(slot[coarse]);
  }
};

/// The columns of one face patch as their non-zero voxels: depth index k (from the box's lower
/// face) and value, in increasing k, column c = iu·nv + iv at [start[c], start[c + 1]).
struct PatchColumns {
  std::int64_t u0 = 0, v0 = 0;
  int nu = 0, nv = 0, depth = 0;
  std::array<std::uint32_t, 65> start{};
  std::vector<int> k;
  std::vector<float> value;
};

void gather(const volume::ColumnReader& reader, std::size_t unit, volume::SparseColumnTile& sparse,
            volume::ColumnTile& dense, PatchColumns& out) {
  std::array<std::uint32_t, 64> count{};
  if (reader.read_sparse(unit, sparse)) {
    out.u0 = sparse.u0;
    out.v0 = sparse.v0;
    out.nu = sparse.nu;
    out.nv = sparse.nv;
    out.depth = sparse.depth;
    for (const auto& sl : sparse.slices) {
      for (std::uint32_t i = sl.begin; i < sl.end; ++i) count[sparse.column[i]] += sparse.value[i] != 0.0f ? 1U : 0U;
    }
    out.start[0] = 0;
    for (std::size_t c = 0; c < 64; ++c) out.start[c + 1] = out.start[c] + count[c];
    out.k.resize(out.start[64]);
    out.value.resize(out.start[64]);
    std::array<std::uint32_t, 64> next{};
    std::copy(out.start.begin(), out.start.begin() + 64, next.begin());
    // Slices come in increasing depth and hold a column at most once: each column's voxels come
    // out in increasing k.
    for (const auto& sl : sparse.slices) {
      for (std::uint32_t i = sl.begin; i < sl.end; ++i) {
        if (sparse.value[i] == 0.0f) continue;
        const std::uint32_t at = next[sparse.column[i]]++;
        out.k[at] = sl.k;
        out.value[at] = sparse.value[i];
      }
    }
    return;
  }
  // A patch under an active tile: its dense columns, non-zero voxels kept.
  reader.read(unit, dense);
  out.u0 = dense.u0;
  out.v0 = dense.v0;
  out.nu = dense.nu;
  out.nv = dense.nv;
  out.depth = dense.depth;
  out.k.clear();
  out.value.clear();
  out.start[0] = 0;
  std::size_t c = 0;
  for (int iu = 0; iu < dense.nu; ++iu) {
    for (int iv = 0; iv < dense.nv; ++iv, ++c) {
      const float* col = dense.column(iu, iv);
      for (int k = 0; k < dense.depth; ++k) {
        if (col[k] == 0.0f) continue;
        out.k.push_back(k);
        out.value.push_back(col[k]);
      }
      out.start[c + 1] = static_cast<std::uint32_t>(out.k.size());
    }
  }
  for (; c < 64; ++c) out.start[c + 1] = out.start[c];
}

/// Two lanes of doubles (GCC and Clang vector extension): the four-lane sums below as two such
/// pairs, the same additions per lane as scalar code, in SSE2 registers.
using Lanes2 = double __attribute__((vector_size(16)));

Lanes2 load2(const double* x) {
  Lanes2 v;
  std::memcpy(&v, x, sizeof v);
  return v;
}

/// Σx and Σx² of xs in four lanes (lane j holds the elements i ≡ j mod 4 of the full groups of
/// four; the rest goes to lane 0): a sum in one running order would wait on the adder at every
/// window.
Sums lane_sums(const std::vector<double>& xs) {
  Lanes2 s01{0.0, 0.0}, s23{0.0, 0.0}, q01{0.0, 0.0}, q23{0.0, 0.0};
  std::size_t i = 0;
  for (; i + 4 <= xs.size(); i += 4) {
    const Lanes2 a = load2(&xs[i]);
    const Lanes2 b = load2(&xs[i + 2]);
    s01 += a;
    s23 += b;
    q01 += a * a;
    q23 += b * b;
  }
  for (; i < xs.size(); ++i) {
    s01[0] += xs[i];
    q01[0] += xs[i] * xs[i];
  }
  return Sums{static_cast<double>(xs.size()), (s01[0] + s01[1]) + (s23[0] + s23[1]),
              (q01[0] + q01[1]) + (q23[0] + q23[1])};
}

/// Σ(x − c)² over xs in the lanes of lane_sums.
double lane_squared_deviations(const std::vector<double>& xs, double c) {
  const Lanes2 cc{c, c};
  Lanes2 q01{0.0, 0.0}, q23{0.0, 0.0};
  std::size_t i = 0;
  for (; i + 4 <= xs.size(); i += 4) {
    const Lanes2 a = load2(&xs[i]) - cc;
    const Lanes2 b = load2(&xs[i + 2]) - cc;
    q01 += a * a;
    q23 += b * b;
  }
  for (; i < xs.size(); ++i) {
    const double dev = xs[i] - c;
    q01[0] += dev * dev;
  }
  return (q01[0] + q01[1]) + (q23[0] + q23[1]);
}

/// Per-thread buffers of add_windows, reused from column to column.
struct WindowScratch {
  std::vector<double> run;
  std::vector<std::uint32_t> rank;
  std::vector<double> means;
};

/// Every window of w voxels of one column (positions 0 … n − w). Windows that cannot hold a
/// voxel — before the first voxel's reach or after the last voxel — have mean exactly 0 and are
/// counted, not visited. Between them a window's sum is a difference of the running sum over
/// the column's voxels in order, read at each end's rank (how many voxels lie before it): that
/// is the dense pass's prefix sum there (a zero voxel adds exactly 0), so every window mean has
/// the same bits as a dense pass's, with no branch per window on where the next voxel is. The
/// column's sums over windows are taken in four lanes and added to the shard's and the group's
/// once per column (docs/benchmarks.md "Validate: predictions against the truth").
void add_windows(const int* k, const float* value, std::size_t count, int n, int w, WindowSummary& part, Group& g,
                 WindowScratch& scratch) {
  const int positions = n - w + 1;
  if (positions <= 0) return;
  std::vector<double>& means = scratch.means;
  if (count == 0) means.clear();  // (resized below without clearing: no zero fill per column)
  if (count > 0) {
    const int s_lo = std::max(0, k[0] - w + 1);
    const int s_hi = std::min(positions - 1, k[count - 1]);
    const auto span = static_cast<std::size_t>(s_hi - s_lo + w);  // voxels s_lo … s_hi + w − 1
    // run[i]: Σ of the first i voxels; rank[x]: how many voxels lie before position s_lo + x.
    // run[rank[x]] is the dense prefix sum at x, without a branch or a chain of additions per
    // position.
    std::vector<double>& run = scratch.run;
    run.resize(count + 1);
    run[0] = 0.0;
    for (std::size_t i = 0; i < count; ++i) run[i + 1] = run[i] + static_cast<double>(value[i]);
    std::vector<std::uint32_t>& rank = scratch.rank;
    rank.assign(span + 1, 0U);
    for (std::size_t i = 0; i < count; ++i) rank[static_cast<std::size_t>(k[i] - s_lo) + 1] = 1U;
    for (std::size_t x = 1; x <= span; ++x) rank[x] += rank[x - 1];
    means.resize(static_cast<std::size_t>(s_hi - s_lo + 1));
    const auto wu = static_cast<std::size_t>(w);
    for (std::size_t i = 0; i < means.size(); ++i) means[i] = (run[rank[i + wu]] - run[rank[i]]) / w;
  }
  const double empty = positions - static_cast<double>(means.size());  // windows without a voxel
  const Sums column_sums = lane_sums(means);
  part.all.merge(column_sums);
  g.windows.merge(column_sums);
  part.all.n += empty;
  g.windows.n += empty;
  // The histogram as (count, sum) pairs, one cache line for both; windows of mean 0 inside the
  // span (gaps between yarns come in runs, so the branch is predictable) are counted.
  double* hist = part.histogram.data();
  std::size_t positive = 0;
  for (const double m : means) {
    if (m > 0.0) {
      const auto b = 2 * static_cast<std::size_t>(bin_of_positive(m));
      hist[b] += 1.0;
      hist[b + 1] += m;
      ++positive;
    }
  }
  part.zeros += empty + static_cast<double>(means.size() - positive);
  // The column's moments about its own mean, merged pairwise into the shard's (moments.h); four
  // partial sums of the squared deviations, and the empty windows' (0 − mean)² at once.
  Moments column;
  column.n = static_cast<std::uint64_t>(positions);
  column.mean = column_sums.s / positions;
  column.m2 = lane_squared_deviations(means, column.mean) + empty * column.mean * column.mean;
  part.moments.merge(column);
}

/// The column's block means (blocks of B from the entry face) into its coarse column: s, s2 and
/// the adjacent-block cross sums; an empty block adds 0 to each, so only blocks with voxels are
/// visited (their count, the closed columns, is added at the merge).
void add_blocks(const int* k, const float* value, std::size_t count, int n, int B, bool reverse, ShardBlocks& sb,
                std::size_t place, std::int64_t nb) {
  sb.rays[place] += 1.0;
  if (count == 0) {
    sb.open[place] += 1.0;
    return;
  }
  sb.closed[place] += 1.0;
  Sums* block = &sb.sums[place * static_cast<std::size_t>(nb)];
  double* pair = &sb.cross[place * static_cast<std::size_t>(nb)];
  int prev_b = -2;
  double prev_m = 0.0;
  int cur_b = -1;
  int b_end = 0;
  double sum = 0.0;
  auto flush = [&] {
    const int e0 = cur_b * B;
    const int e1 = std::min(n, e0 + B);
    const double m = sum / (e1 - e0);
    block[cur_b].s += m;
    block[cur_b].s2 += m * m;
    if (prev_b == cur_b - 1) pair[prev_b] += prev_m * m;
    prev_b = cur_b;
    prev_m = m;
  };
  for (std::size_t j = 0; j < count; ++j) {
    const std::size_t i = reverse ? count - 1 - j : j;
    const int e = reverse ? n - 1 - k[i] : k[i];  // depth from the entry face
    if (e >= b_end) {                             // a new block (no division per voxel)
      if (cur_b >= 0) flush();
      cur_b = e / B;
      b_end = (cur_b + 1) * B;
      sum = 0.0;
    }
    sum += static_cast<double>(value[i]);
  }
  flush();
}

}  // namespace

ColumnPass column_pass(const volume::ColumnReader& reader, bool reverse, int w, ProgressSink& progress) {
  const int axis = reader.axis();
  const auto box = reader.box();
  const auto au = static_cast<std::size_t>((axis + 1) % 3);
  const auto av = static_cast<std::size_t>((axis + 2) % 3);
  const auto ext = box.extent();
  const int n = static_cast<int>(ext[static_cast<std::size_t>(axis)]);
  ColumnPass out;
  BlockStats& st = out.blocks;
  st.nu = (ext[au] + w - 1) / w;
  st.nv = (ext[av] + w - 1) / w;
  st.nb = (n + w - 1) / w;
  const auto coarse = static_cast<std::size_t>(st.nu * st.nv);
  const std::size_t cells = coarse * static_cast<std::size_t>(st.nb);
  if (cells > 50'000'000) fail("local fields: {} blocks of {} voxels is too many", cells, w);
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  std::vector<WindowSummary> parts(shards);
  std::vector<ShardBlocks> blocks(shards);
  ProgressTask task(progress, fmt::format("statistics {}", "xyz"[axis]), units);
  parallel_units(shards, [&](std::size_t shard) {
    volume::SparseColumnTile sparse;
    volume::ColumnTile dense;
    PatchColumns cols;
    WindowScratch scratch;
    auto& part = parts[shard];
    part.histogram.assign(2 * static_cast<std::size_t>(kBins), 0.0);
    auto& sb = blocks[shard];
    sb.slot.assign(coarse, -1);
    Group* group = nullptr;
    GroupKey group_key{};
    for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
      gather(reader, unit, sparse, dense, cols);
      for (int iu = 0; iu < cols.nu; ++iu) {
        for (int iv = 0; iv < cols.nv; ++iv) {
          const auto c = static_cast<std::size_t>(iu * cols.nv + iv);
          const int* k = cols.k.data() + cols.start[c];
          const float* value = cols.value.data() + cols.start[c];
          const std::size_t count = cols.start[c + 1] - cols.start[c];
          // Groups and coarse columns anchored at the active box's lower corner.
          const std::int64_t gu = (cols.u0 + iu - box.min[au]) / w;
          const std::int64_t gv = (cols.v0 + iv - box.min[av]) / w;
          // Neighbouring columns share a group: the map is searched only when it changes.
          if (group == nullptr || gu != group_key.first || gv != group_key.second) {
            group_key = {gu, gv};
            group = &part.groups[group_key];
          }
          Group& g = *group;
          g.rays += 1.0;
          add_windows(k, value, count, n, w, part, g, scratch);
          const auto coarse_column = static_cast<std::size_t>(gu * st.nv + gv);
          add_blocks(k, value, count, n, w, reverse, sb, sb.place(coarse_column, st.nb), st.nb);
        }
      }
      task.step();
    }
  });
  // Shard by shard in shard order: the same sums for any thread count. A shard that does not
  // touch a coarse column would add exact zeros to it.
  WindowSummary& ws = out.windows;
  ws.bin_count.assign(kBins, 0.0);
  ws.bin_sum.assign(kBins, 0.0);
  st.sums.assign(cells, Sums{});
  st.cross.assign(cells, 0.0);
  st.rays.assign(coarse, 0.0);
  st.open.assign(coarse, 0.0);
  for (std::size_t sh = 0; sh < shards; ++sh) {
    const auto& p = parts[sh];
    ws.all.merge(p.all);
    ws.moments.merge(p.moments);
    const double zeros = p.zeros;
    ws.zeros += zeros;
    // The non-zero windows' sums are the sums of all windows (a zero window adds exactly 0).
    ws.nonzero.merge(Sums{p.all.n - zeros, p.all.s, p.all.s2});
    for (std::size_t b = 0; b < static_cast<std::size_t>(kBins); ++b) {
      ws.bin_count[b] += p.histogram[2 * b];
      ws.bin_sum[b] += p.histogram[2 * b + 1];
    }
    for (const auto& [key, g] : p.groups) {
      auto& dst = ws.groups[key];
      dst.windows.merge(g.windows);
      dst.rays += g.rays;
    }
    const auto& sb = blocks[sh];
    for (std::size_t place = 0; place < sb.touched.size(); ++place) {
      const std::size_t c = sb.touched[place];
      for (std::size_t b = 0; b < static_cast<std::size_t>(st.nb); ++b) {
        const std::size_t from = place * static_cast<std::size_t>(st.nb) + b;
        Sums s = sb.sums[from];
        s.n = sb.closed[place];
        st.sums[c * static_cast<std::size_t>(st.nb) + b].merge(s);
        st.cross[c * static_cast<std::size_t>(st.nb) + b] += sb.cross[from];
      }
      st.rays[c] += sb.rays[place];
      st.open[c] += sb.open[place];
    }
  }
  return out;
}

}  // namespace weft::fit::detail
