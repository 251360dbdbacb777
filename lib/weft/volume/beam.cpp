#include "weft/volume/beam.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>

#include "weft/core/error.h"
#include "weft/core/fp_hold.h"
#include "weft/core/parallel.h"
#include "weft/core/parse_number.h"
#include "weft/core/rng.h"
#include "weft/volume/columns.h"
#include "weft/volume/dda.h"
#include "weft/volume/dda_impl.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/lattice.h"

namespace weft::volume {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::size_t kMaxShards = 64;  // fixed, so reductions do not depend on the thread count

using Vec3 = std::array<double, 3>;

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

using Lattice = BeamLattice;

Lattice make_lattice(const Grid& grid, const BeamSpec& spec) {
  return make_beam_lattice(active_world_box(grid), grid.voxel_size(), spec);
}

/// Profiles from the streaming pass (axis beams): τ at voxel boundaries by prefix sums, then
/// linear interpolation (exact: τ is linear inside a voxel) onto the depth grid; handed over
/// one face patch at a time.
/// `consume_sparse(shard, tile, reverse, mu_h)`, unless it is nullptr, takes the patches whose
/// depth grid is the voxel boundaries and whose columns are all kept, as their active voxels
/// (SparseColumnTile) instead of dense τ profiles.
template <typename Consumer, typename SparseConsumer>
void stream_columns(const Grid& grid, const Lattice& L, double scale, ProgressSink& progress, Consumer&& consume,
                    SparseConsumer&& consume_sparse) {
  constexpr bool kSparse = !std::is_same_v<std::decay_t<SparseConsumer>, std::nullptr_t>;
  const ColumnReader reader(grid, L.axis);
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kMaxShards, units);
  const bool reverse = L.d[L.axis] < 0.0;
  const IndexBox box = reader.box();
  const int ua = (L.axis + 1) % 3;
  const int va = (L.axis + 2) % 3;
  const auto ext_v = static_cast<std::uint64_t>(box.extent()[va]);
  const std::size_t K = L.depths.size();
  // The default depth grid is the voxel boundaries: τ is then the prefix sum itself.
  // (to rounding: the box length is a difference of world coordinates).
  bool on_boundaries = true;
  for (std::size_t q = 0; q < K && on_boundaries; ++q) {
    on_boundaries = std::abs(L.depths[q] - static_cast<double>(q) * L.h) <= 1e-12 * L.h * static_cast<double>(q + 1);
  }
  ProgressTask task(progress, "beam " + direction_label(L.d) + " (streaming)", units);
  const bool sparse = kSparse && on_boundaries && L.stride == 1;
  parallel_units(shards, [&](std::size_t shard) {
    ColumnTile tile;
    SparseColumnTile sparse_tile;
    TauBlock block;
    std::vector<double> boundary;
    const std::size_t begin = shard * units / shards;
    const std::size_t end = (shard + 1) * units / shards;
    const double mu_h = scale * L.h;
    for (std::size_t unit = begin; unit < end; ++unit) {
      if constexpr (kSparse) {
        // (Patches are 8×8 columns: add_sparse keeps a 64-bit set of changed columns.)
        if (sparse && reader.read_sparse(unit, sparse_tile) && static_cast<std::size_t>(sparse_tile.depth) + 1 == K &&
            sparse_tile.nu * sparse_tile.nv <= 64) {
          consume_sparse(shard, sparse_tile, reverse, mu_h);
          task.step();
          continue;
        }
      }
      reader.read(unit, tile);
      const int n = tile.depth;
      boundary.assign(static_cast<std::size_t>(n) + 1, 0.0);
      block.ray.clear();
      block.cols = 0;
      const std::size_t max_cols = static_cast<std::size_t>(tile.nu) * static_cast<std::size_t>(tile.nv);
      block.stride = max_cols;
      block.tau.resize(max_cols * K);
      const std::size_t stride = block.stride;
      if (on_boundaries && static_cast<std::size_t>(n) + 1 == K && tile.nv <= 8) {
        // τ at the voxel boundaries is the prefix sum itself. The columns of a row of the patch
        // are summed side by side: independent chains (no add latency stall) and contiguous
        // writes of one depth's row.
        const auto nv = static_cast<std::size_t>(tile.nv);
        std::array<double, 8> acc{};
        for (int iu = 0; iu < tile.nu; ++iu) {
          const float* base = tile.column(iu, 0);
          double* out = block.tau.data() + static_cast<std::size_t>(iu) * nv;
          acc.fill(0.0);
          for (std::size_t iv = 0; iv < nv; ++iv) out[iv] = 0.0;
          for (int k = 0; k < n; ++k) {
            const auto src = static_cast<std::size_t>(reverse ? n - 1 - k : k);
            double* row = out + (static_cast<std::size_t>(k) + 1) * stride;
            for (std::size_t iv = 0; iv < nv; ++iv) {
              acc[iv] += static_cast<double>(base[iv * static_cast<std::size_t>(n) + src]);
              row[iv] = mu_h * acc[iv];
            }
          }
        }
        block.cols = max_cols;
        for (int iu = 0; iu < tile.nu; ++iu) {
          for (int iv = 0; iv < tile.nv; ++iv) {
            block.ray.push_back(static_cast<std::uint64_t>(tile.u0 + iu - box.min[ua]) * ext_v +
                                static_cast<std::uint64_t>(tile.v0 + iv - box.min[va]));
          }
        }
      } else {
        for (int iu = 0; iu < tile.nu; ++iu) {
          for (int iv = 0; iv < tile.nv; ++iv) {
            const float* col = tile.column(iu, iv);
            double acc = 0.0;
            for (int k = 0; k < n; ++k) {
              boundary[static_cast<std::size_t>(k) + 1] = acc += static_cast<double>(col[reverse ? n - 1 - k : k]);
            }
            double* out = block.tau.data() + block.cols;
            for (std::size_t q = 0; q < K; ++q) {
              const double p = L.depths[q] / L.h;
              const auto j = std::min<std::int64_t>(static_cast<std::int64_t>(std::floor(p)), n - 1);
              const auto ju = static_cast<std::size_t>(j);
              out[q * stride] =
                  mu_h * (boundary[ju] + (p - static_cast<double>(j)) * (boundary[ju + 1] - boundary[ju]));
            }
            block.ray.push_back(static_cast<std::uint64_t>(tile.u0 + iu - box.min[ua]) * ext_v +
                                static_cast<std::uint64_t>(tile.v0 + iv - box.min[va]));
            ++block.cols;
          }
        }
      }
      if (L.stride > 1) {
        // A thinned beam: keep the chosen columns, moved to the front of every depth row.
        std::size_t kept = 0;
        for (std::size_t c = 0; c < block.cols; ++c) {
          const std::uint64_t ray = block.ray[c];
          if (!L.keeps(static_cast<std::int64_t>(ray / ext_v), static_cast<std::int64_t>(ray % ext_v))) continue;
          for (std::size_t q = 0; q < K; ++q) block.tau[q * stride + kept] = block.tau[q * stride + c];
          block.ray[kept++] = ray;
        }
        block.cols = kept;
        block.ray.resize(kept);
      }
      if (block.cols > 0) consume(shard, block);
      task.step();
    }
  });
}

/// Profiles traced ray by ray, by weft's DDA or OpenVDB's.
template <typename Consumer>
void trace_rays(const Grid& grid, const Lattice& L, double scale, bool use_openvdb, ProgressSink& progress,
                Consumer&& consume) {
  const auto units = static_cast<std::size_t>(L.na);
  const std::size_t shards = std::min(kMaxShards, units);
  ProgressTask task(progress, "beam " + direction_label(L.d) + (use_openvdb ? " (openvdb dda)" : " (dda)"), units);
  const auto& vdb = *grid.impl().grid;
  parallel_units(shards, [&](std::size_t shard) {
    Tracer tracer(grid);
    auto acc = vdb.getConstAccessor();
    const detail::CellBox box = detail::active_cell_box(vdb);
    std::vector<double> tau(L.depths.size());
    std::vector<std::array<double, 2>> offsets;
    const std::size_t begin = shard * units / shards;
    const std::size_t end = (shard + 1) * units / shards;
    for (std::size_t i = begin; i < end; ++i) {
      for (std::int64_t j = 0; j < L.nb; ++j) {
        const auto ii = static_cast<std::int64_t>(i);
        if (!L.keeps(ii, j)) continue;
        L.offsets(ii, j, offsets);
        for (int r = 0; r < L.per_cell; ++r) {
          const auto& off = offsets[static_cast<std::size_t>(r)];
          Ray ray{L.ray_origin(ii, j, off[0], off[1]), L.d};
          if (L.axis < 0) {
            const BoxHit hit = tracer.intersect_active_box(ray, 0.0);
            if (!hit.hit) continue;
            for (int c = 0; c < 3; ++c) ray.origin[c] += hit.t_enter * ray.direction[c];
          }
          ProfileBuilder pb{L.depths, tau.data()};
          const detail::CellRay cr = detail::to_cell_ray(vdb, ray);
          if (!use_openvdb) {
            detail::march_cells(acc, cr, box, 0.0, L.depths.back(),
                                [&](double t0, double t1, float v, const std::int64_t*, int) {
                                  return pb.add(t0, t1, scale * static_cast<double>(v));
                                });
          } else {
            double t0 = 0.0;
            double t1 = L.depths.back();
            if (detail::clip(cr, box, t0, t1)) {
              using VRay = openvdb::math::Ray<double>;
              // math::Ray stores 1/d, ±inf for an axis-aligned ray, and its DDA relies on it.
              const HeldFpExceptions hold;
              const VRay vray(openvdb::Vec3d(cr.o[0], cr.o[1], cr.o[2]), openvdb::Vec3d(cr.d[0], cr.d[1], cr.d[2]), t0,
                              t1);
              openvdb::math::DDA<VRay, 0> dda(vray, t0, t1);
              do {
                const double ta = dda.time();
                const double tb = dda.next();
                float v = 0.0f;
                if (!acc.probeValue(dda.voxel(), v)) v = 0.0f;
                if (tb > ta && !pb.add(ta, tb, scale * static_cast<double>(v))) break;
              } while (dda.step());
            }
          }
          pb.finish();
          consume(shard, L.ray_index(ii, j, r), tau.data());
        }
      }
      task.step();
    }
  });
}

}  // namespace

std::vector<double> beam_depths(const Grid& grid, const BeamSpec& spec) {
  if (grid.active_voxel_count() == 0) fail("beam: grid '{}' has no active voxels", grid.name());
  return make_lattice(grid, spec).depths;
}

namespace {

void check_spec(const Grid& grid, const BeamSpec& spec) {
  require_positive("beam: scale (sigma)", spec.scale);
  if (spec.rays_per_column < 1) fail("beam: rays per column must be >= 1, got {}", spec.rays_per_column);
  if (spec.column_stride < 1 || spec.column_stride > 4096) {
    fail("beam: column stride must be in 1..4096, got {}", spec.column_stride);
  }
  if (spec.depth_step != 0.0) require_positive("beam: depth step", spec.depth_step);
  // The first active value, not a count of them all (a parallel pass over every leaf).
  if (!grid.impl().grid->tree().cbeginValueOn()) fail("beam: grid '{}' has no active voxels", grid.name());
  (void)unit_direction(spec.direction, "beam");
  if (spec.method == BeamMethod::streaming && beam_axis(spec.direction) < 0) {
    fail("beam: the streaming method needs an axis direction, got {}", direction_label(spec.direction));
  }
}

template <typename BlockConsumer, typename RayConsumer, typename SparseConsumer>
void run_beam(const Grid& grid, const BeamSpec& spec, const Lattice& L, ProgressSink& progress,
              BlockConsumer&& consume_block, RayConsumer&& consume, SparseConsumer&& consume_sparse,
              std::string& method_name) {
  BeamMethod method = spec.method;
  if (method == BeamMethod::automatic) method = L.axis >= 0 ? BeamMethod::streaming : BeamMethod::per_ray;
  method_name = to_string(method);
  if (method == BeamMethod::streaming) {
    stream_columns(grid, L, spec.scale, progress, consume_block, consume_sparse);
  } else {
    trace_rays(grid, L, spec.scale, method == BeamMethod::openvdb_dda, progress, consume);
  }
}

}  // namespace

std::string to_string(BeamMethod method) {
  switch (method) {
    case BeamMethod::automatic:
      return "auto";
    case BeamMethod::streaming:
      return "streaming";
    case BeamMethod::per_ray:
      return "per-ray";
    case BeamMethod::openvdb_dda:
      return "openvdb";
  }
  return "?";
}

BeamMethod parse_beam_method(const std::string& text) {
  if (text == "auto") return BeamMethod::automatic;
  if (text == "streaming") return BeamMethod::streaming;
  if (text == "per-ray") return BeamMethod::per_ray;
  if (text == "openvdb") return BeamMethod::openvdb_dda;
  fail("beam method '{}' is not one of auto, streaming, per-ray, openvdb", text);
}

double TransmittanceCurve::transmittance(std::size_t k) const { return std::exp(log_t.at(k)); }

std::array<double, 3> parse_direction(const std::string& text) {
  std::string s = text;
  double sign = 1.0;
  if (!s.empty() && (s[0] == '+' || s[0] == '-') && s.size() == 2) {
    sign = s[0] == '-' ? -1.0 : 1.0;
    s = s.substr(1);
  }
  if (s == "x" || s == "X") return {sign, 0.0, 0.0};
  if (s == "y" || s == "Y") return {0.0, sign, 0.0};
  if (s == "z" || s == "Z") return {0.0, 0.0, sign};
  std::array<double, 3> d{};
  std::istringstream in(text);
  std::string part;
  int n = 0;
  while (std::getline(in, part, ',')) {
    if (n >= 3) fail("direction '{}': expected x, y, z (optionally signed) or three numbers dx,dy,dz", text);
    const std::optional<double> v = parse_number(part);
    if (!v) fail("direction '{}': '{}' is not a number", text, part);
    d[static_cast<std::size_t>(n)] = *v;
    ++n;
  }
  if (n != 3) fail("direction '{}': expected x, y, z (optionally signed) or three numbers dx,dy,dz", text);
  (void)unit_direction(d, fmt::format("direction '{}'", text).c_str());
  return d;
}

int beam_axis(const std::array<double, 3>& d) {
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (d[a] != 0.0) {
      if (axis >= 0) return -1;
      axis = a;
    }
  }
  return axis;
}

std::string direction_label(const std::array<double, 3>& d) {
  const int a = beam_axis(d);
  if (a >= 0) return fmt::format("{}{}", d[a] < 0.0 ? "-" : "+", "xyz"[a]);
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return fmt::format("({:.4g}, {:.4g}, {:.4g})", d[0] / len, d[1] / len, d[2] / len);
}

TransmittanceCurve measure_beam(const Grid& grid, const BeamSpec& spec, ProgressSink& progress) {
  check_spec(grid, spec);
  const Lattice L = make_lattice(grid, spec);
  const std::size_t shards = kMaxShards;
  std::vector<LseAccumulator> parts(shards, LseAccumulator(L.depths.size()));
  std::vector<std::pair<std::vector<double>, std::vector<double>>> scratch(shards);  // one per shard: no sharing
  std::vector<LseAccumulator::SparseScratch> sparse_scratch(shards);
  TransmittanceCurve curve;
  run_beam(
      grid, spec, L, progress,
      [&](std::size_t shard, const TauBlock& block) {
        parts[shard].add_block(block, scratch[shard].first, scratch[shard].second);
      },
      [&](std::size_t shard, std::uint64_t, const double* tau) { parts[shard].add(tau); },
      [&](std::size_t shard, const SparseColumnTile& tile, bool reverse, double mu_h) {
        parts[shard].add_sparse(tile, reverse, mu_h, sparse_scratch[shard]);
      },
      curve.method);
  LseAccumulator total(L.depths.size());
  for (const auto& p : parts) total.merge(p);
  curve.depth = L.depths;
  curve.direction = L.d;
  // Rays of one axis column cross the same voxels: they are one sample, counted once.
  const auto per_cell = static_cast<std::uint64_t>(L.per_cell);
  const bool streamed = curve.method == "streaming";
  curve.rays = streamed ? total.n * per_cell : total.n;
  const std::uint64_t independent = (L.axis >= 0 && !streamed) ? total.n / per_cell : total.n;
  curve.distinct_rays = independent;
  total.finish(curve, independent);
  if (total.n == 0) fail("beam {}: no ray entered the grid", direction_label(L.d));
  return curve;
}

BeamDepths beam_optical_depths(const Grid& grid, const BeamSpec& spec) {
  check_spec(grid, spec);
  const Lattice L = make_lattice(grid, spec);
  BeamDepths out;
  out.depth = L.depths;
  const std::uint64_t count =
      static_cast<std::uint64_t>(L.na) * static_cast<std::uint64_t>(L.nb) *
      static_cast<std::uint64_t>(
          L.axis >= 0 && spec.method != BeamMethod::per_ray && spec.method != BeamMethod::openvdb_dda ? 1 : L.per_cell);
  if (count > 4'000'000) fail("beam optical depths: {} rays is too many to return", count);
  out.tau.assign(count, {});
  std::string method;
  const std::size_t K = L.depths.size();
  run_beam(
      grid, spec, L, null_progress(),
      [&](std::size_t, const TauBlock& block) {
        for (std::size_t c = 0; c < block.cols; ++c) {
          auto& row = out.tau[block.ray[c]];
          row.resize(K);
          for (std::size_t k = 0; k < K; ++k) row[k] = block.tau[k * block.stride + c];
        }
      },
      [&](std::size_t, std::uint64_t ray, const double* tau) { out.tau[ray].assign(tau, tau + K); }, nullptr, method);
  // Rays of a general direction that miss the box leave empty rows.
  std::erase_if(out.tau, [](const std::vector<double>& row) { return row.empty(); });
  return out;
}

ScattererCurves measure_scatterer(const Grid& grid, const ScattererSpec& spec, ProgressSink& progress) {
  require_positive("scatterer rays: scale (sigma)", spec.scale);
  if (spec.rays < 2) fail("scatterer rays: need at least 2 rays, got {}", spec.rays);
  if (grid.active_voxel_count() == 0) fail("scatterer rays: grid '{}' has no active voxels", grid.name());
  const double total = grid.sum();
  if (!(total > 0.0)) fail("scatterer rays: grid '{}' holds no particles (all values 0)", grid.name());
  const Vec3 fixed = spec.fixed_direction ? unit_direction(spec.direction, "scatterer rays") : Vec3{0, 0, 1};
  const auto& vdb = *grid.impl().grid;
  const double h = grid.voxel_size();
  const IndexBox box = grid.active_bbox();
  const auto ext = box.extent();
  const auto o = grid.origin();
  // Cumulative weights over active voxels and tiles: origins ∝ C.
  std::vector<openvdb::CoordBBox> cells;
  std::vector<double> cdf;
  double run = 0.0;
  for (auto it = vdb.cbeginValueOn(); it; ++it) {
    if (!(*it > 0.0f)) continue;
    openvdb::CoordBBox b;
    it.getBoundingBox(b);
    run += static_cast<double>(*it) * static_cast<double>(it.getVoxelCount());
    cells.push_back(b);
    cdf.push_back(run);
  }
  double diag = 0.0;
  for (int a = 0; a < 3; ++a) diag += std::pow(h * static_cast<double>(ext[a]), 2);
  diag = std::sqrt(diag);
  const double max_depth = spec.max_depth > 0.0 ? spec.max_depth : diag;
  const std::vector<double> depths = beam_depth_grid(max_depth, spec.depth_step > 0.0 ? spec.depth_step : h);
  constexpr std::uint64_t kChunk = 1024;
  const std::uint64_t units = (spec.rays + kChunk - 1) / kChunk;
  const std::size_t shards = static_cast<std::size_t>(std::min<std::uint64_t>(kMaxShards, units));
  std::vector<LseAccumulator> s_parts(shards, LseAccumulator(depths.size()));
  std::vector<LseAccumulator> q_parts(shards, LseAccumulator(depths.size()));
  ProgressTask task(progress, "scatterer/source rays", units);
  parallel_units(shards, [&](std::size_t shard) {
    Tracer tracer(grid);
    std::vector<double> tau(depths.size());
    const std::uint64_t begin = shard * units / shards;
    const std::uint64_t end = (shard + 1) * units / shards;
    for (std::uint64_t u = begin; u < end; ++u) {
      Pcg32 rng = stream_for(spec.seed, u);
      const std::uint64_t n = std::min(kChunk, spec.rays - u * kChunk);
      for (std::uint64_t r = 0; r < n; ++r) {
        Vec3 dir = fixed;
        if (!spec.fixed_direction) {
          const double z = 1.0 - 2.0 * rng.uniform();
          const double phi = 2.0 * M_PI * rng.uniform();
          const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
          dir = {s * std::cos(phi), s * std::sin(phi), z};
        }
        // Particle origin: a cell ∝ its weight, then uniform inside it.
        const double pick = rng.uniform() * run;
        const auto idx = static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), pick) - cdf.begin());
        const auto& b = cells[std::min(idx, cells.size() - 1)];
        Ray sray;
        for (int a = 0; a < 3; ++a) {
          const double lo = o[a] + h * b.min()[a];
          const double span = h * static_cast<double>(b.max()[a] - b.min()[a] + 1);
          sray.origin[a] = lo + span * rng.uniform();
        }
        sray.direction = dir;
        Ray qray;
        for (int a = 0; a < 3; ++a)
          qray.origin[a] = o[a] + h * (box.min[a] + static_cast<double>(ext[a]) * rng.uniform());
        qray.direction = dir;
        tau = tracer.optical_depth_profile(sray, depths, spec.scale);
        s_parts[shard].add(tau.data());
        tau = tracer.optical_depth_profile(qray, depths, spec.scale);
        q_parts[shard].add(tau.data());
      }
      task.step();
    }
  });
  LseAccumulator s_total(depths.size());
  LseAccumulator q_total(depths.size());
  for (std::size_t i = 0; i < shards; ++i) {
    s_total.merge(s_parts[i]);
    q_total.merge(q_parts[i]);
  }
  ScattererCurves out;
  for (auto* c : {&out.t_s, &out.t_q}) {
    c->depth = depths;
    c->rays = spec.rays;
    c->distinct_rays = spec.rays;
    c->direction = fixed;
    c->method = spec.fixed_direction ? "fixed direction" : "isotropic directions";
  }
  s_total.finish(out.t_s, s_total.n);
  q_total.finish(out.t_q, q_total.n);
  out.mean_extinction =
      spec.scale * total / (static_cast<double>(ext[0]) * static_cast<double>(ext[1]) * static_cast<double>(ext[2]));
  const std::size_t K = depths.size();
  out.p_q.assign(K, 0.0);
  out.mu_t_s.assign(K, 0.0);
  for (std::size_t k = 0; k < K; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1;
    const std::size_t b = k + 1 < K ? k + 1 : K - 1;
    if (b > a) out.p_q[k] = -(out.t_q.transmittance(b) - out.t_q.transmittance(a)) / (depths[b] - depths[a]);
    out.mu_t_s[k] = out.mean_extinction * out.t_s.transmittance(k);
  }
  return out;
}

}  // namespace weft::volume
