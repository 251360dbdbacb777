#pragma once
/// @file
/// @brief The one pass over an axis beam's columns that every predictive model of fit/models.h is
/// built from: the window means of length L (the window statistics, the histogram of Eq. 16, the
/// across-beam groups) and the block statistics of the local models (fit/local_models.h).
///
/// Why one pass, and why sparse: a cloth fills a small part of its active box (a knit about an
/// eighth), and most windows of a column hold no fibre. The pass reads each face patch once as
/// its active voxels column by column (volume::ColumnReader::read_columns), so it costs the
/// active voxels and the pieces of equal window means, not the box: a window without a voxel is
/// counted, not visited (docs/benchmarks.md "Validate: predictions against the truth", "Validate:
/// cheaper predictions, continued").

#include <cstdint>
#include <cstring>
#include <map>
#include <utility>
#include <vector>

#include "weft/core/progress.h"
#include "weft/fit/local_models.h"
#include "weft/fit/moments.h"
#include "weft/volume/columns.h"

namespace weft::fit::detail {

// Histogram of window means for Eq. 16: kSub bins per octave over kOctaves octaves of m (2^-41
// to 2^23; mean concentrations and extinctions in 1/mm lie far inside).
inline constexpr int kSub = 128;
inline constexpr int kOctaves = 64;
inline constexpr int kMinExponent = -40;
inline constexpr int kBins = kSub * kOctaves;

using GroupKey = std::pair<std::int64_t, std::int64_t>;

struct Group {
  Sums windows;
  double rays = 0.0;
};

/// Everything the windows of length w along the columns give.
struct WindowSummary {
  Sums all;
  Moments moments;  ///< the same windows, per column about its own mean, merged: what validate reports
  Sums nonzero;     ///< the windows with m > 0
  double zeros = 0.0;
  std::map<GroupKey, Group> groups;  ///< transverse cells of w × w columns
  std::vector<double> bin_count;     ///< per bin of bin_of
  std::vector<double> bin_sum;
  /// A shard's bins that hold windows, in increasing bin: (bin, count, sum). Only those: a bin
  /// without windows adds exact zeros at the merge, and the shards' full histograms were 128 KB each.
  struct BinSums {
    std::size_t bin = 0;
    double count = 0.0;
    double sum = 0.0;
  };
  std::vector<BinSums> histogram;
};

/// The histogram bin of a window mean m > 0: kSub bins per octave of m (the octave from the
/// binary exponent), so no range has to be known before the pass; means below the lowest octave
/// share bin 0, above the highest the last bin (each bin is evaluated at its own mean).
/// bin_of(m) for m > 0 without a branch (what a pass over many windows wants; the same bin).
/// For m > 0 the bits below the sign are the biased exponent, then the mantissa: bits >> 45 is
/// exponent·kSub + the sub-bin, and bin_of's bin that minus the first octave's start (three
/// instructions and the clamp instead of taking the two fields apart: one call per piece of
/// every column in the statistics pass).
[[nodiscard]] inline int bin_of_positive(double m) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &m, sizeof bits);
  static_assert(kSub == 128, "seven mantissa bits per octave");
  const std::int64_t b = static_cast<std::int64_t>(bits >> 45U) - std::int64_t{1022 + kMinExponent} * kSub;
  return static_cast<int>(b < 0 ? 0 : (b >= kBins ? kBins - 1 : b));
}

[[nodiscard]] inline int bin_of(double m) {
  // m = f·2^e with f in [0.5, 1): e is the biased exponent − 1022, and the kSub sub-bins of an
  // octave are the top bits of the mantissa ((f − 0.5)·2·kSub, exactly). Subnormals fall below.
  std::uint64_t bits = 0;
  std::memcpy(&bits, &m, sizeof bits);
  const int e = static_cast<int>((bits >> 52) & 0x7ffU) - 1022;
  if (e < kMinExponent) return 0;
  if (e >= kMinExponent + kOctaves) return kBins - 1;
  static_assert(kSub == 128, "seven mantissa bits per octave");
  return (e - kMinExponent) * kSub + static_cast<int>((bits >> 45) & 0x7fU);
}

struct ColumnPass {
  WindowSummary windows;
  BlockStats blocks;
};

/// Which of the pass's two statistics to gather (fit/model_selection.h): the windows cost most of
/// the pass, the blocks little beyond reading the columns. A part not asked for stays empty.
struct PassParts {
  bool windows = true;
  bool blocks = true;
  bool profile = true;  ///< with the blocks: the mean's depth profile inside them (BlockStats::slices)
};

/// Windows of w voxels (every position, stride one) and blocks of w³ voxels (anchored to the
/// cloth: docs/validate.md "Blocks anchored to the cloth") along the reader's axis, the beam
/// entering from the upper face when `reverse`. Shards of face patches, merged in shard order:
/// the same bytes for any thread count; each part's sums are the same whether the other is gathered.
[[nodiscard]] ColumnPass column_pass(const volume::ColumnReader& reader, bool reverse, int w, PassParts parts,
                                     ProgressSink& progress);

}  // namespace weft::fit::detail
