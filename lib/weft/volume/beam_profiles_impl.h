#pragma once
/// @file
/// @brief The passes that produce a beam's optical depth profiles (internal; not installed): the
/// streaming pass over the active voxel columns of an axis beam (stream_columns) and the ray by
/// ray tracing by weft's DDA or OpenVDB's (trace_rays), both handing their profiles to a
/// consumer per shard. Templated on the consumers so the hot loops inline them. Include only
/// from .cpp files of lib/weft/volume (it includes OpenVDB).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>

#include "weft/core/fp_hold.h"
#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/volume/beam.h"
#include "weft/volume/beam_accumulate_impl.h"
#include "weft/volume/columns.h"
#include "weft/volume/dda.h"
#include "weft/volume/dda_impl.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/lattice.h"

namespace weft::volume::detail {

using Lattice = BeamLattice;

/// Work between two progress reports of a thread (~ms at ~10⁸–10⁹ steps/s): what bounds the
/// time a stop request waits (docs/python.md "Interrupting a call").
constexpr double kReportSteps = 1 << 20;

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
  ProgressTask task(progress, "beam " + direction_label(L.d) + " [streaming]", units, "column tiles");
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

/// The cell-space ray of the lattice ray from `offset` (world, relative to the box's lower
/// corner), relative to the box's lowest voxel: a scale-translate map takes a world length to
/// cells by its inverse scale alone, so the ray's numbers are the same wherever the box sits.
/// An axis beam's entry coordinate is the box face itself (0 or the box's extent), exactly.
inline CellRay box_cell_ray(const CellMap& map, const Lattice& L, const std::array<double, 3>& offset,
                            const CellBox& rel) {
  CellRay r{};
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    r.o[a] = offset[i] * map.index.inv_scale[a];
    r.d[a] = L.d[i] * map.index.inv_scale[a];
    r.sgn[a] = r.d[a] > 0.0 ? 1 : (r.d[a] < 0.0 ? -1 : 0);
    r.inv[a] = r.sgn[a] != 0 ? 1.0 / r.d[a] : 0.0;
  }
  if (L.axis >= 0) r.o[L.axis] = r.sgn[L.axis] > 0 ? 0.0 : static_cast<double>(rel.hi[L.axis]);
  return r;
}

/// Profiles traced ray by ray, by weft's DDA or OpenVDB's.
template <typename Consumer>
void trace_rays(const Grid& grid, const Lattice& L, double scale, bool use_openvdb, ProgressSink& progress,
                Consumer&& consume) {
  const auto units = static_cast<std::size_t>(L.na);
  const std::size_t shards = std::min(kMaxShards, units);
  // Progress counts ray slots (every cell's per_cell rays, kept or not), reported after every
  // `batch` of them: about kReportSteps of work, so a stop request (Ctrl-C acts at a report)
  // is seen within milliseconds however many rays a row of cells holds.
  const auto per_cell = static_cast<std::uint64_t>(L.per_cell);
  const std::uint64_t slots = static_cast<std::uint64_t>(L.na) * static_cast<std::uint64_t>(L.nb) * per_cell;
  const double ray_steps = L.cells_crossed() + static_cast<double>(L.depths.size());
  const auto batch = static_cast<std::uint64_t>(std::max(1.0, std::floor(kReportSteps / ray_steps)));
  // The label names the method as the curve does (TransmittanceCurve::method, measure's summary).
  ProgressTask task(progress, "beam " + direction_label(L.d) + (use_openvdb ? " [openvdb]" : " [per-ray]"), slots,
                    "rays");
  const auto& vdb = *grid.impl().grid;
  const CellMap map(vdb);
  // Every weft grid's map is scale-translate: its rays are walked relative to the box's lowest
  // voxel (box_cell_ray). Any other map is walked in its own index space.
  const CellBox abs_box = active_cell_box(vdb);
  CellBox box = abs_box;
  const std::int64_t* base = nullptr;
  if (map.scale_translate) {
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = 0;
      box.hi[a] = abs_box.hi[a] - abs_box.lo[a];
    }
    base = abs_box.lo;
  }
  parallel_units(shards, [&](std::size_t shard) {
    auto acc = vdb.getConstAccessor();
    std::vector<double> tau(L.depths.size());
    std::uint64_t pending = 0;  // ray slots not yet reported
    const auto report = [&](std::uint64_t n) {
      pending += n;
      if (pending >= batch) {
        task.step(pending);
        pending = 0;
      }
    };
    const std::size_t begin = shard * units / shards;
    const std::size_t end = (shard + 1) * units / shards;
    for (std::size_t i = begin; i < end; ++i) {
      for (std::int64_t j = 0; j < L.nb; ++j) {
        const auto ii = static_cast<std::int64_t>(i);
        if (!L.keeps(ii, j)) {
          report(per_cell);
          continue;
        }
        CellOffsets offsets = L.offsets(ii, j);
        for (int r = 0; r < L.per_cell; ++r) {
          report(1);
          const std::array<double, 2> off = offsets.next();
          std::array<double, 3> offset = L.ray_offset(ii, j, off[0], off[1]);
          if (L.axis < 0) {
            // The chord in the box's own frame (lattice.h), shared with the fibre and fields beams.
            const Lattice::Chord c = L.chord(offset);
            if (!L.traces_chord(c)) continue;
            for (int a = 0; a < 3; ++a) offset[a] += c.t_enter * L.d[a];
          }
          ProfileBuilder pb{L.depths, tau.data()};
          detail::CellRay cr{};
          if (base != nullptr) {
            cr = box_cell_ray(map, L, offset, box);
          } else {
            Ray ray{offset, L.d};
            for (int a = 0; a < 3; ++a) ray.origin[a] += L.box_lo[a];
            cr = detail::to_cell_ray(map, ray);
          }
          if (!use_openvdb) {
            detail::march_cells(
                acc, cr, box, 0.0, L.depths.back(),
                [&](double t0, double t1, float v, const std::int64_t*, int) {
                  return pb.add(t0, t1, scale * static_cast<double>(v));
                },
                base);
          } else {
            // OpenVDB's DDA walks the tree's own index space: the ray moved back to it.
            if (base != nullptr) {
              for (int a = 0; a < 3; ++a) cr.o[a] += static_cast<double>(base[a]);
            }
            double t0 = 0.0;
            double t1 = L.depths.back();
            if (detail::clip(cr, abs_box, t0, t1)) {
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
    }
    task.step(pending);
  });
}

}  // namespace weft::volume::detail
