// The predictive models' one sparse pass over an axis beam's columns (fit/column_pass.h).
#include "weft/fit/column_pass.h"

#include <algorithm>
#include <array>
#include <tuple>

#include <tbb/enumerable_thread_specific.h>

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
  std::vector<double> slices;  ///< [place·depth + k]: Σ of the values at depth k (the profile)
  std::size_t depth = 0;       ///< slices per place (0: no profile)

  std::size_t place(std::size_t coarse, std::int64_t nb) {
    if (slot[coarse] < 0) {
      slot[coarse] = static_cast<std::int32_t>(touched.size());
      touched.push_back(coarse);
      sums.resize(sums.size() + static_cast<std::size_t>(nb));
      cross.resize(cross.size() + static_cast<std::size_t>(nb), 0.0);
      slices.resize(slices.size() + depth, 0.0);
      rays.push_back(0.0);
      open.push_back(0.0);
      closed.push_back(0.0);
    }
    return static_cast<std::size_t>(slot[coarse]);
  }
};

/// The columns of one face patch as their active voxels (volume::SparseColumns): read straight
/// from the leaves, or, for a patch under an active tile, from its dense columns. A voxel of
/// value 0 adds exactly 0 to every sum and is skipped by the passes below.
void gather(const volume::ColumnReader& reader, std::size_t unit, volume::ColumnTile& dense,
            volume::SparseColumns& out) {
  if (reader.read_columns(unit, out)) return;
  reader.read(unit, dense);
  out.u0 = dense.u0;
  out.v0 = dense.v0;
  out.nu = dense.nu;
  out.nv = dense.nv;
  out.depth0 = dense.depth0;
  out.depth = dense.depth;
  out.count.fill(0U);
  const auto depth = static_cast<std::size_t>(out.depth);
  if (out.k.size() < 64 * depth) {
    out.k.resize(64 * depth);
    out.value.resize(64 * depth);
  }
  std::size_t c = 0;
  for (int iu = 0; iu < dense.nu; ++iu) {
    for (int iv = 0; iv < dense.nv; ++iv, ++c) {
      const float* col = dense.column(iu, iv);
      for (int k = 0; k < dense.depth; ++k) {
        if (col[k] == 0.0f) continue;
        const std::size_t at = c * depth + out.count[c]++;
        out.k[at] = k;
        out.value[at] = col[k];
      }
    }
  }
}

/// Two lanes of doubles (GCC and Clang vector extension): the four-lane sums below as two such
/// pairs, the same additions per lane as scalar code, in SSE2 registers.
using Lanes2 = double __attribute__((vector_size(16)));

Lanes2 load2(const double* x) {
  Lanes2 v;
  std::memcpy(&v, x, sizeof v);
  return v;
}

/// Σ len·x, Σ len·x² over `count` pieces (a window mean x held by len windows) in four lanes
/// (lane j holds the pieces i ≡ j mod 4 of the full groups of four; the rest goes to lane 0): a
/// sum in one running order would wait on the adder at every piece.
std::pair<double, double> lane_sums(const double* x, const double* len, std::size_t count) {
  Lanes2 s01{0.0, 0.0}, s23{0.0, 0.0}, q01{0.0, 0.0}, q23{0.0, 0.0};
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) {
    const Lanes2 a = load2(&x[i]);
    const Lanes2 b = load2(&x[i + 2]);
    const Lanes2 la = load2(&len[i]) * a;
    const Lanes2 lb = load2(&len[i + 2]) * b;
    s01 += la;
    s23 += lb;
    q01 += la * a;
    q23 += lb * b;
  }
  for (; i < count; ++i) {
    const double l = len[i] * x[i];
    s01[0] += l;
    q01[0] += l * x[i];
  }
  return {(s01[0] + s01[1]) + (s23[0] + s23[1]), (q01[0] + q01[1]) + (q23[0] + q23[1])};
}

/// Σ len·(x − c)² over the pieces in the lanes of lane_sums.
double lane_squared_deviations(const double* x, const double* len, std::size_t count, double c) {
  const Lanes2 cc{c, c};
  Lanes2 q01{0.0, 0.0}, q23{0.0, 0.0};
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) {
    const Lanes2 a = load2(&x[i]) - cc;
    const Lanes2 b = load2(&x[i + 2]) - cc;
    q01 += load2(&len[i]) * a * a;
    q23 += load2(&len[i + 2]) * b * b;
  }
  for (; i < count; ++i) {
    const double dev = x[i] - c;
    q01[0] += len[i] * dev * dev;
  }
  return (q01[0] + q01[1]) + (q23[0] + q23[1]);
}

/// The histogram of a shard while its columns are read: (count, sum) per bin, plus one bin for
/// the windows of mean 0 inside a column's span. One copy per bin: consecutive pieces differ by
/// a voxel entering or leaving and share a bin for 0.6 % of the pieces on the 12×12 knit, so a
/// second copy (kept while the pass visited windows, which often share one) only doubled the
/// histogram's footprint and its cache misses (docs/benchmarks.md "Validate: cheaper predictions,
/// third pass"). Folded into the shard's bins with windows when the shard ends: the counts are
/// exact, the sums added in piece order.
inline constexpr std::size_t kZeroBin = kBins;

/// Per-thread buffers of add_windows, reused from column to column.
struct WindowScratch {
  std::vector<double> run;
  std::vector<std::uint64_t> voxel;  ///< bit x: a voxel at position s_lo + x of the column
  std::vector<double> mean;          ///< per piece: the mean of its windows
  std::vector<double> length;        ///< per piece: its windows
  std::vector<double> bins;          ///< [bin·2]: count, sum; bins 0 … kZeroBin
};

/// Bits [x, x + 64) of a bit string as one word (the string padded with a zero word).
std::uint64_t bits_at(const std::uint64_t* words, std::size_t x) {
  const std::size_t q = x >> 6U;
  const std::size_t b = x & 63U;
  return b == 0 ? words[q] : (words[q] >> b) | (words[q + 1] << (64U - b));
}

/// Every window of w voxels of one column (positions 0 … n − w). Windows that cannot hold a
/// voxel — before the first voxel's reach or after the last voxel — have mean exactly 0 and are
/// counted, not visited. Between them a window's sum changes only where a voxel enters it or
/// leaves it, so the span's windows fall into pieces of equal means, and each piece is visited
/// once with its number of windows (on a knit 43 % of the windows start a piece). A window's sum
/// is the difference of the running sum over the column's voxels in order, read at the number of
/// voxels before each end — the dense pass's prefix sums there (a zero voxel adds exactly 0) — so
/// every window mean has the same bits as a dense pass's; those counts change only at a piece's
/// start, by the voxel leaving and the voxel entering there. The column's sums over windows are
/// Σ len·m and Σ len·m² over pieces, in four lanes, added to the shard's and the group's once per
/// column (docs/benchmarks.md "Validate: cheaper predictions, continued").
void add_windows(const int* k, const float* value, std::size_t count, int n, int w, WindowSummary& part, Group& g,
                 WindowScratch& scratch) {
  const int positions = n - w + 1;
  if (positions <= 0) return;
  std::size_t pieces = 0;
  std::size_t windows = 0;  // in the span
  if (count > 0) {
    const int s_lo = std::max(0, k[0] - w + 1);
    const int s_hi = std::min(positions - 1, k[count - 1]);
    windows = static_cast<std::size_t>(s_hi - s_lo) + 1U;
    const auto wu = static_cast<std::size_t>(w);
    // run[i]: Σ of the first i voxels.
    std::vector<double>& run = scratch.run;
    if (run.size() < count + 1) run.resize(count + 1);  // grown only: a resize up zero-fills
    run[0] = 0.0;
    for (std::size_t i = 0; i < count; ++i) run[i + 1] = run[i] + static_cast<double>(value[i]);
    // The voxels' positions as bits, padded so that bits_at reads whole words past the span.
    std::vector<std::uint64_t>& voxel = scratch.voxel;
    const std::size_t words = (windows + wu + 63) / 64 + 2;
    if (voxel.size() < words + 4) voxel.resize(words + 4);
    std::size_t ahead = 0;  // voxels before position w: the count at window 0's far end
    // The positions increase, so a word is built in a register and stored when the next voxel
    // lies past it (an OR into memory per voxel would wait on the previous voxel's store), and
    // every word is written once, the words without a voxel as 0 (no memset of the string: on a
    // short column the call cost as much as the bits).
    std::uint64_t word_bits = 0;
    std::size_t word_at = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const auto x = static_cast<std::size_t>(k[i] - s_lo);
      if ((x >> 6U) != word_at) {
        voxel[word_at] = word_bits;
        word_bits = 0;
        while (++word_at < (x >> 6U)) voxel[word_at] = 0;
      }
      word_bits |= std::uint64_t{1} << (x & 63U);
      ahead += x < wu ? 1U : 0U;
    }
    voxel[word_at] = word_bits;
    // The words past the last voxel's up to `words` (at most (w + 63)/64 + 2): four stores
    // without a loop cover a window of up to 128 voxels (a loop GCC turns into a memset call).
    std::uint64_t* tail = voxel.data() + word_at + 1;
    tail[0] = 0;
    tail[1] = 0;
    tail[2] = 0;
    tail[3] = 0;
    if (word_at + 5 < words) std::fill(tail + 4, voxel.data() + words, std::uint64_t{0});
    if (scratch.mean.size() < windows) {
      scratch.mean.resize(windows);
      scratch.length.resize(windows);
    }
    double* mean = scratch.mean.data();
    double* length = scratch.length.data();
    double* bins = scratch.bins.data();
    // A piece into the arrays and the histogram (without a branch: a piece of mean 0, a gap inside
    // the span, goes to kZeroBin).
    const auto emit = [&](double x, double len) {
      mean[pieces] = x;
      length[pieces] = len;
      const std::size_t b = x > 0.0 ? static_cast<std::size_t>(bin_of_positive(x)) : kZeroBin;
      // (count, sum) of the bin as one pair: one load and one store per piece.
      double* slot = &bins[b * 2];
      Lanes2 pair = load2(slot);
      pair += Lanes2{len, len * x};
      std::memcpy(slot, &pair, sizeof pair);
      ++pieces;
    };
    std::size_t behind = 0;  // voxels before the piece's first window
    std::size_t start = 0;
    double m = (run[ahead] - run[behind]) / w;
    const std::uint64_t* bits = voxel.data();
    for (std::size_t word = 0; word * 64 < windows; ++word) {
      // Window i = 64·word + t starts a piece when voxel i + w − 1 enters or voxel i − 1 leaves.
      const std::uint64_t enter = bits_at(bits, word * 64 + wu - 1);
      const std::uint64_t leave = word == 0 ? bits[0] << 1U : bits_at(bits, word * 64 - 1);
      std::uint64_t starts = enter | leave;
      if (word == 0) starts &= ~std::uint64_t{1};  // window 0's piece is open already
      if (windows - word * 64 < 64) starts &= (std::uint64_t{1} << (windows - word * 64)) - 1;
      for (; starts != 0; starts &= starts - 1) {
        const auto t = static_cast<unsigned>(__builtin_ctzll(starts));
        const std::size_t i = word * 64 + t;
        emit(m, static_cast<double>(static_cast<std::int64_t>(i - start)));  // signed: one conversion, no branch
        behind += (leave >> t) & 1U;
        ahead += (enter >> t) & 1U;
        m = (run[ahead] - run[behind]) / w;
        start = i;
      }
    }
    emit(m, static_cast<double>(windows - start));
  }
  const double* mean = scratch.mean.data();
  const double* length = scratch.length.data();
  const double empty = positions - static_cast<double>(windows);  // windows without a voxel
  const auto [sum, sum2] = lane_sums(mean, length, pieces);
  const Sums column_sums{static_cast<double>(windows), sum, sum2};
  part.all.merge(column_sums);
  g.windows.merge(column_sums);
  part.all.n += empty;
  g.windows.n += empty;
  part.zeros += empty;
  // The column's moments about its own mean, merged pairwise into the shard's (moments.h); four
  // partial sums of the squared deviations, and the empty windows' (0 − mean)² at once.
  Moments column;
  column.n = static_cast<std::uint64_t>(positions);
  column.mean = column_sums.s / positions;
  column.m2 = lane_squared_deviations(mean, length, pieces, column.mean) + empty * column.mean * column.mean;
  part.moments.merge(column);
}

/// The shard's bins with windows into its histogram and its windows of mean 0 inside spans into
/// `zeros`; the bins are left zero for the thread's next shard.
void fold_bins(std::vector<double>& bins, WindowSummary& part) {
  part.histogram.clear();
  for (std::size_t b = 0; b < static_cast<std::size_t>(kBins); ++b) {
    double* cs = &bins[b * 2];
    if (cs[0] > 0.0) {
      part.histogram.push_back({b, cs[0], cs[1]});
      cs[0] = 0.0;
      cs[1] = 0.0;
    }
  }
  double* z = &bins[kZeroBin * 2];
  part.zeros += z[0];
  z[0] = 0.0;
  z[1] = 0.0;
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
  double* profile = sb.depth > 0 ? &sb.slices[place * sb.depth] : nullptr;
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
    if (profile != nullptr) profile[e] += static_cast<double>(value[i]);
  }
  flush();
}

}  // namespace

ColumnPass column_pass(const volume::ColumnReader& reader, bool reverse, int w, PassParts want,
                       ProgressSink& progress) {
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
  const std::size_t cells = want.blocks ? coarse * static_cast<std::size_t>(st.nb) : 0;
  const bool profile = want.blocks && want.profile;
  st.depth = profile ? n : 0;
  // The profile holds w values per block: a window of a few voxels on a large box would take
  // gigabytes, refused before the pass like the blocks themselves.
  // Both limits bound the pass's memory before it starts (each cell a few doubles per shard
  // that touches it); a larger scale L means fewer blocks and coarse columns.
  const char* axis_name = axis == 0 ? "x" : (axis == 1 ? "y" : "z");
  if (cells > 50'000'000)
    fail(
        "local fields along {}: {} blocks of side {} voxel{} is too many (at most 5e7): the scale L (window) is too "
        "small for this grid's box",
        axis_name, cells, w, w == 1 ? "" : "s");
  if (profile && coarse * static_cast<std::size_t>(n) > 100'000'000)
    fail(
        "local fields along {}: the prediction's depth profile, {} slices in each of {} coarse columns of side {} "
        "voxel{}, is too many (at most 1e8): the scale L (window) is too small for this grid's box",
        axis_name, n, coarse, w, w == 1 ? "" : "s");
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  std::vector<WindowSummary> parts(shards);
  std::vector<ShardBlocks> blocks(shards);
  ProgressTask task(progress, fmt::format("statistics {}", "xyz"[axis]), units);
  // A thread's buffers, reused from shard to shard (their contents never reach a result: every
  // column fills what it reads, and the histogram bins are zero between shards): fresh ones per
  // shard were 0.4 MB and more to allocate and zero, 64 times per axis.
  struct Buffers {
    volume::ColumnTile dense;
    volume::SparseColumns cols;
    WindowScratch scratch;
  };
  tbb::enumerable_thread_specific<Buffers> buffers;
  parallel_units(shards, [&](std::size_t shard) {
    Buffers& own = buffers.local();
    volume::ColumnTile& dense = own.dense;
    volume::SparseColumns& cols = own.cols;
    WindowScratch& scratch = own.scratch;
    auto& part = parts[shard];
    if (scratch.bins.empty()) scratch.bins.assign((kZeroBin + 1) * 2, 0.0);
    auto& sb = blocks[shard];
    if (want.blocks) sb.slot.assign(coarse, -1);
    sb.depth = static_cast<std::size_t>(st.depth);
    Group* group = nullptr;
    GroupKey group_key{};
    for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
      gather(reader, unit, dense, cols);
      // Groups and coarse columns anchored at the active box's lower corner: a patch's row and
      // column indices divided once (two integer divisions per column were a wait of tens of
      // cycles each on the z axis's short columns).
      std::array<std::int64_t, std::tuple_size_v<decltype(cols.count)>> group_v{};
      for (int iv = 0; iv < cols.nv; ++iv) group_v[static_cast<std::size_t>(iv)] = (cols.v0 + iv - box.min[av]) / w;
      for (int iu = 0; iu < cols.nu; ++iu) {
        const std::int64_t gu = (cols.u0 + iu - box.min[au]) / w;
        for (int iv = 0; iv < cols.nv; ++iv) {
          const std::size_t c =
              static_cast<std::size_t>(iu) * static_cast<std::size_t>(cols.nv) + static_cast<std::size_t>(iv);
          const int* k = cols.k.data() + c * static_cast<std::size_t>(cols.depth);
          const float* value = cols.value.data() + c * static_cast<std::size_t>(cols.depth);
          const std::size_t count = cols.count[c];
          const std::int64_t gv = group_v[static_cast<std::size_t>(iv)];
          if (want.windows) {
            // Neighbouring columns share a group: the map is searched only when it changes.
            if (group == nullptr || gu != group_key.first || gv != group_key.second) {
              group_key = {gu, gv};
              group = &part.groups[group_key];
            }
            Group& g = *group;
            g.rays += 1.0;
            add_windows(k, value, count, n, w, part, g, scratch);
          }
          if (want.blocks) {
            const auto coarse_column = static_cast<std::size_t>(gu * st.nv + gv);
            add_blocks(k, value, count, n, w, reverse, sb, sb.place(coarse_column, st.nb), st.nb);
          }
        }
      }
      task.step();
    }
    fold_bins(scratch.bins, part);
  });
  // Shard by shard in shard order: the same sums for any thread count. A shard that does not
  // touch a coarse column would add exact zeros to it.
  WindowSummary& ws = out.windows;
  ws.bin_count.assign(kBins, 0.0);
  ws.bin_sum.assign(kBins, 0.0);
  st.sums.assign(cells, Sums{});
  st.cross.assign(cells, 0.0);
  st.rays.assign(want.blocks ? coarse : 0, 0.0);
  st.open.assign(want.blocks ? coarse : 0, 0.0);
  st.slices.assign(coarse * static_cast<std::size_t>(st.depth), 0.0);
  for (std::size_t sh = 0; sh < shards; ++sh) {
    const auto& p = parts[sh];
    ws.all.merge(p.all);
    ws.moments.merge(p.moments);
    const double zeros = p.zeros;
    ws.zeros += zeros;
    // The non-zero windows' sums are the sums of all windows (a zero window adds exactly 0).
    ws.nonzero.merge(Sums{p.all.n - zeros, p.all.s, p.all.s2});
    for (const auto& h : p.histogram) {
      ws.bin_count[h.bin] += h.count;
      ws.bin_sum[h.bin] += h.sum;
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
      for (std::size_t k = 0; k < sb.depth; ++k) st.slices[c * sb.depth + k] += sb.slices[place * sb.depth + k];
    }
  }
  return out;
}

}  // namespace weft::fit::detail
