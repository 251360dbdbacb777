#pragma once
/// @file
/// @brief The local models of fit/models.h (internal to the module): statistics of blocks of
/// side L anchored to the cloth, and the beam's transmittance through them with each memory of
/// the gamma hazard, including the prediction (docs/validate.md "The prediction").

#include <algorithm>
#include <cstdint>
#include <vector>

#include "weft/core/progress.h"
#include "weft/volume/columns.h"

namespace weft::fit::detail {

inline constexpr std::size_t kShards = 64;  // fixed: results do not depend on the thread count

/// Plain sums (Σ1, Σx, Σx²) of window means: exact to merge in any fixed order.
struct Sums {
  double n = 0.0;
  double s = 0.0;
  double s2 = 0.0;
  void add(double x) {
    n += 1.0;
    s += x;
    s2 += x * x;
  }
  void merge(const Sums& o) {
    n += o.n;
    s += o.s;
    s2 += o.s2;
  }
  [[nodiscard]] double mean() const { return n > 0.0 ? s / n : 0.0; }
  [[nodiscard]] double var() const {
    if (!(n > 0.0)) return 0.0;
    const double m = s / n;
    return std::max(0.0, s2 / n - m * m);
  }
};

enum class Memory { none, from_entry, per_block };

/// Block statistics of the beam's columns: blocks of B voxels anchored to the cloth, not to the
/// index lattice (docs/validate.md "Blocks anchored to the cloth"): across the beam at the active
/// box's lower corner, along it at the face where the beam enters (block 0 holds the first B
/// voxels every ray crosses, as the memory of the hazard starts there), clipped to the box, so
/// that a block holds exactly the columns (rays) of the beam that cross it and a translated copy
/// of the voxels gives the same blocks. Per block: the mean of C and the variance of the column
/// means over the block's length across its columns (Eq. 19 per block).
struct BlockStats {
  std::int64_t nu = 0, nv = 0, nb = 0;
  /// [(cu·nv + cv)·nb + cb], cb counted from the entry face: over the columns that hold some
  /// concentration along the beam (an open column, empty over the whole depth, adds only zeros)
  std::vector<Sums> sums;
  std::vector<double> rays;  ///< per coarse column (cu, cv): beam columns in it
  std::vector<double> open;  ///< per coarse column: its columns empty over the whole depth
  /// [(cu·nv + cv)·nb + cb]: Σ over the columns of (mean in block cb) × (mean in block cb + 1)
  std::vector<double> cross;
  /// The depth profile of the mean inside the blocks (only when gathered: PassParts::profile):
  /// [(cu·nv + cv)·depth + k], Σ over the coarse column's columns of the value at depth k from
  /// the entry face; `depth` slices per coarse column (0 when not gathered).
  std::int64_t depth = 0;
  std::vector<double> slices;
  [[nodiscard]] std::size_t index(std::int64_t u, std::int64_t v, std::int64_t b) const {
    return static_cast<std::size_t>((u * nv + v) * nb + b);
  }
  /// Over the columns that hold concentration.
  [[nodiscard]] const Sums& closed(std::int64_t u, std::int64_t v, std::int64_t b) const {
    return sums[index(u, v, b)];
  }
  /// Over every column of the block (open ones add n only: x + 0.0 is x, so the sums are those
  /// of all columns bit for bit).
  [[nodiscard]] Sums at(std::int64_t u, std::int64_t v, std::int64_t b) const {
    Sums all = sums[index(u, v, b)];
    all.n += open[static_cast<std::size_t>(u * nv + v)];
    return all;
  }
};

/// log T on `depths` of the beam through block fields: per coarse column the hazard of each
/// block integrated exactly, T the ray-weighted mean over coarse columns.
[[nodiscard]] std::vector<double> block_field_curve(int n, int B, double h, double sigma, const BlockStats& st,
                                                    Memory memory, const std::vector<double>& depths);

/// The prediction (docs/validate.md "The prediction"): a ray's concentration in block b is
/// C̄_b · P · Q_b, P ~ Gamma(mean 1, relative variance v_p) one per ray for its whole path (the
/// part that persists from block to block: which yarn or gap the ray runs in), Q_b ~ Gamma(mean
/// 1, v_b) one per ray and block (the part that does not), with (1 + v_p)(1 + v_b) = 1 + the
/// block's relative variance of column means. Given P, blocks are independent gamma laws
/// (the renewal); over P the memory runs from the entry. T(t) = E_P Π_b (1 + σC̄_b P s_b v_b)^(−1/v_b)
/// per coarse column, E_P by kNodes equal-probability quantiles of P.
[[nodiscard]] std::vector<double> two_scale_curve(int n, int B, double h, double sigma, const BlockStats& st,
                                                  const std::vector<double>& depths);

}  // namespace weft::fit::detail
