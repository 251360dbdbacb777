#pragma once
/// @file
/// @brief The accumulators of a beam's rays (internal; not installed): per depth the mean of
/// exp(−τ_i) and of exp(−2τ_i) in log-sum-exp form (LseAccumulator), fed one ray, one dense
/// face patch (TauBlock) or one sparse patch at a time, and the builder of one ray's τ profile
/// on the depth grid from its segments (ProfileBuilder). T_gt(t) = mean over rays of
/// exp(−τ_i(t)) (docs/architecture.md §6). Include only from .cpp files of lib/weft/volume.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "weft/volume/beam.h"
#include "weft/volume/columns.h"

namespace weft::volume::detail {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::size_t kMaxShards = 64;  // fixed, so reductions do not depend on the thread count

/// The optical depths of the columns of one face patch on the depth grid, depth-major
/// (tau[k·cols + c]), so that per-depth reductions over the columns are contiguous loops.
struct TauBlock {
  std::size_t cols = 0;
  std::size_t stride = 0;  ///< distance between depths in `tau` (≥ cols)
  std::vector<double> tau;
  std::vector<std::uint64_t> ray;  ///< lattice index of each column
};

/// Mean of exp(−τ_i) and of exp(−2τ_i) per depth, in log-sum-exp form: value = e^m · s.
struct LseAccumulator {
  std::vector<double> m;
  std::vector<double> s1;
  std::vector<double> s2;
  std::uint64_t n = 0;

  explicit LseAccumulator(std::size_t k = 0) : m(k, -kInf), s1(k, 0.0), s2(k, 0.0) {}

  void add(const double* tau, std::uint64_t weight = 1) {
    const auto w = static_cast<double>(weight);
    for (std::size_t k = 0; k < m.size(); ++k) {
      const double x = -tau[k];
      if (x > m[k]) {
        const double r = std::exp(m[k] - x);
        s1[k] = s1[k] * r + w;
        s2[k] = s2[k] * r * r + w;
        m[k] = x;
      } else {
        const double e = std::exp(x - m[k]);
        s1[k] += w * e;
        s2[k] += w * e * e;
      }
    }
    n += weight;
  }

  /// Largest growth of a patch's smallest τ before its shift c moves (add_block, add_sparse).
  static constexpr double kRebase = 64.0;

  /// Adds the rays of a patch: per depth a sum of exp(−(τ − c)) over the patch, merged with one
  /// exp. The shift c is the patch's smallest τ, moved only when that has grown by more than
  /// kRebase (so every term stays in [e^−kRebase·…, 1] and the largest never underflows). With
  /// c fixed, a ray whose τ did not change since the previous depth (gaps between yarns, where
  /// most rays spend most depths) has the same term, reused bit for bit: far fewer exp() calls
  /// than one per ray and depth.
  void add_block(const TauBlock& b, std::vector<double>& prev_tau, std::vector<double>& prev_e) {
    const std::size_t nc = b.cols;
    prev_tau.assign(nc, -1.0);
    prev_e.assign(nc, 0.0);
    double shift = 0.0;
    for (std::size_t k = 0; k < m.size(); ++k) {
      const double* row = b.tau.data() + k * b.stride;
      std::array<double, 4> lo4{row[0], row[0], row[0], row[0]};
      std::size_t c4 = 0;
      for (; c4 + 4 <= nc; c4 += 4) {
        for (std::size_t u = 0; u < 4; ++u) lo4[u] = std::min(lo4[u], row[c4 + u]);
      }
      for (; c4 < nc; ++c4) lo4[0] = std::min(lo4[0], row[c4]);
      const double lo = std::min(std::min(lo4[0], lo4[1]), std::min(lo4[2], lo4[3]));
      const bool rebase = lo - shift > kRebase;
      if (rebase) shift = lo;
      double a1 = 0.0;
      double a2 = 0.0;
      for (std::size_t c = 0; c < nc; ++c) {
        double e = prev_e[c];
        if (rebase || row[c] != prev_tau[c]) {
          e = std::exp(shift - row[c]);
          prev_tau[c] = row[c];
          prev_e[c] = e;
        }
        a1 += e;
        a2 += e * e;
      }
      add_at(k, -shift, a1, a2);
    }
    n += nc;
  }

  /// Adds e^x·a1 and e^x·a2 to depth k's sums (a1, a2 > 0).
  void add_at(std::size_t k, double x, double a1, double a2) {
    if (s1[k] == 0.0) {
      m[k] = x;
      s1[k] = a1;
      s2[k] = a2;
    } else if (x == m[k]) {
      s1[k] += a1;  // = a1·exp(0): the common case of one shift for the whole beam
      s2[k] += a2;
    } else if (x < m[k]) {
      const double r = std::exp(x - m[k]);
      s1[k] += a1 * r;
      s2[k] += a2 * r * r;
    } else {
      const double r = std::exp(m[k] - x);
      s1[k] = s1[k] * r + a1;
      s2[k] = s2[k] * r * r + a2;
      m[k] = x;
    }
  }

  /// The state of add_sparse for one patch (≤ 64 columns), kept per shard.
  struct SparseScratch {
    std::array<double, 64> acc{};  ///< Σ value along each column so far
    std::array<double, 64> tau{};  ///< μh·acc: τ at the current depth
    std::array<double, 64> e{};    ///< exp(shift − τ)
    std::array<double, 64> p1{};   ///< prefix sums of e over the columns
    std::array<double, 64> p2{};   ///< prefix sums of e²
  };

  /// The same sums as add_block on the dense τ of the patch (bit for bit: same shifts, same
  /// terms, same summation order), in work that follows the active voxels: τ of a column changes
  /// only at its active voxels, so the per-depth sum over the patch changes only at depths with
  /// active voxels. There the changed terms are recomputed and the prefix sums over the columns
  /// redone from the first changed column on; every other depth adds the previous sums again.
  /// `mu_h` = scale × voxel size; the depth grid must be the voxel boundaries (K = depth + 1).
  void add_sparse(const SparseColumnTile& t, bool reverse, double mu_h, SparseScratch& w) {
    const auto nc = static_cast<std::size_t>(t.nu) * static_cast<std::size_t>(t.nv);
    const std::size_t K = m.size();
    std::fill_n(w.acc.begin(), nc, 0.0);
    std::fill_n(w.tau.begin(), nc, 0.0);
    std::fill_n(w.e.begin(), nc, 1.0);  // exp(0 − 0)
    double a1 = 0.0;
    double a2 = 0.0;
    for (std::size_t c = 0; c < nc; ++c) {
      w.p1[c] = a1 += 1.0;
      w.p2[c] = a2 += 1.0;
    }
    double shift = 0.0;
    double lo = 0.0;       // min over the columns of τ
    std::size_t next = 0;  // the first depth not yet added
    const std::size_t ns = t.slices.size();
    for (std::size_t q = 0; q < ns; ++q) {
      const SparseColumnTile::Slice& sl = t.slices[reverse ? ns - 1 - q : q];
      // τ changes at the far boundary of the slice's voxels: depth index j + 1 for voxel j.
      const std::size_t k = static_cast<std::size_t>(reverse ? t.depth - 1 - sl.k : sl.k) + 1;
      for (; next < k; ++next) add_at(next, -shift, a1, a2);
      std::size_t first = nc;  // first column whose τ changed
      std::uint64_t changed = 0;
      bool rescan = false;  // a column at the minimum τ changed: find the minimum again
      for (std::uint32_t i = sl.begin; i < sl.end; ++i) {
        const std::size_t c = t.column[i];
        w.acc[c] += static_cast<double>(t.value[i]);
        const double tau = mu_h * w.acc[c];
        if (tau != w.tau[c]) {
          rescan = rescan || w.tau[c] == lo;
          lo = std::min(lo, tau);
          w.tau[c] = tau;
          changed |= std::uint64_t{1} << c;
          first = std::min(first, c);
        }
      }
      if (changed != 0) {
        if (rescan) {
          lo = w.tau[0];
          for (std::size_t c = 1; c < nc; ++c) lo = std::min(lo, w.tau[c]);
        }
        if (lo - shift > kRebase) {
          shift = lo;
          for (std::size_t c = 0; c < nc; ++c) w.e[c] = std::exp(shift - w.tau[c]);
          first = 0;
        } else {
          for (std::uint64_t bits = changed; bits != 0; bits &= bits - 1) {
            const auto c = static_cast<std::size_t>(__builtin_ctzll(bits));
            w.e[c] = std::exp(shift - w.tau[c]);
          }
        }
        a1 = first == 0 ? 0.0 : w.p1[first - 1];
        a2 = first == 0 ? 0.0 : w.p2[first - 1];
        for (std::size_t c = first; c < nc; ++c) {
          const double e = w.e[c];
          w.p1[c] = a1 += e;
          w.p2[c] = a2 += e * e;
        }
      }
      add_at(k, -shift, a1, a2);
      next = k + 1;
    }
    for (; next < K; ++next) add_at(next, -shift, a1, a2);
    n += nc;
  }

  void merge(const LseAccumulator& o) {
    for (std::size_t k = 0; k < m.size(); ++k) {
      if (o.s1[k] == 0.0) continue;
      if (s1[k] == 0.0) {
        m[k] = o.m[k];
        s1[k] = o.s1[k];
        s2[k] = o.s2[k];
        continue;
      }
      const double mm = std::max(m[k], o.m[k]);
      const double ra = std::exp(m[k] - mm);
      const double rb = std::exp(o.m[k] - mm);
      s1[k] = s1[k] * ra + o.s1[k] * rb;
      s2[k] = s2[k] * ra * ra + o.s2[k] * rb * rb;
      m[k] = mm;
    }
    n += o.n;
  }

  void finish(TransmittanceCurve& c, std::uint64_t independent) const {
    c.log_t.assign(m.size(), 0.0);
    c.rel_stderr.assign(m.size(), 0.0);
    if (n == 0) return;
    const auto nn = static_cast<double>(n);
    const auto ni = static_cast<double>(independent);
    for (std::size_t k = 0; k < m.size(); ++k) {
      c.log_t[k] = m[k] + std::log(s1[k] / nn);
      // Var(X)/E[X]² = n·Σw²/(Σw)² − 1, scale-free so it survives underflow of T itself.
      const double rel_var = std::max(0.0, nn * s2[k] / (s1[k] * s1[k]) - 1.0);
      c.rel_stderr[k] = independent > 1 ? std::sqrt(rel_var / (ni - 1.0)) : 0.0;
    }
  }
};

/// Fills τ at increasing depths from contiguous segments (t0, t1, μ) in order.
struct ProfileBuilder {
  const std::vector<double>& depths;
  double* tau;
  std::size_t k = 0;
  double acc = 0.0;
  bool add(double t0, double t1, double mu) {
    while (k < depths.size() && depths[k] <= t1) {
      tau[k] = acc + mu * std::max(0.0, depths[k] - t0);
      ++k;
    }
    acc += mu * (t1 - t0);
    return k < depths.size();
  }
  void finish() {
    for (; k < depths.size(); ++k) tau[k] = acc;
  }
};

}  // namespace weft::volume::detail
