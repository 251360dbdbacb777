#pragma once
/// @file
/// @brief The voxel step of weft's one DDA (Amanatides & Woo 1987) without OpenVDB: the ray in
/// cell space, the clip to a box, the step from voxel to voxel. The tree walk (dda_impl.h,
/// inside volume/) steps through a leaf with it; the dense walk below takes the same step (the
/// same clip, first cell and exits) through a small grid's active box copied into an array,
/// moving a record index, for hot loops outside volume/ that read several channels per voxel
/// (the local-gamma medium, docs/render.md §5b "Dense walk").

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "weft/volume/dda.h"

namespace weft::volume {
namespace detail {

/// A ray in "cell space" u = index + ½, where voxel i covers u ∈ [i, i+1): the half-open
/// convention makes face, edge and corner cases a matter of floor().
struct CellRay {
  double o[3];
  double d[3];    ///< cell-space displacement per world unit of t
  double inv[3];  ///< 1/d, unused where sgn = 0
  int sgn[3];     ///< −1, 0, +1; −0.0 counts as 0
};

/// A scale-translate world → index map (every grid weft writes), applied with OpenVDB's own
/// arithmetic bit for bit (ScaleTranslateMap::applyInverseMap / applyInverseJacobian).
struct IndexMap {
  double translation[3] = {0.0, 0.0, 0.0};
  double inv_scale[3] = {1.0, 1.0, 1.0};
};

/// Throws weft::Error naming what is wrong with `ray` (a non-finite origin or direction, or a
/// direction of no length) or with the range [tmin, tmax] (NaN).
[[noreturn]] void fail_bad_ray(const Ray& ray, double tmin, double tmax);

/// The ray's direction divided by its length; throws (fail_bad_ray) as every march does for a
/// bad ray. Inline: a medium starts a walk per flight and per shadow ray.
inline std::array<double, 3> unit_direction(const Ray& ray) {
  const auto& o = ray.origin;
  const auto& d = ray.direction;
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  // A direction component that is infinite or NaN makes len infinite or NaN: no test of its own.
  if (!(std::isfinite(o[0]) && std::isfinite(o[1]) && std::isfinite(o[2]) && len > 0.0 && std::isfinite(len)))
    fail_bad_ray(ray, 0.0, 0.0);
  return {d[0] / len, d[1] / len, d[2] / len};
}

/// The cell-space ray of index-space origin `oi` and direction `di`.
inline CellRay cell_ray(const double* oi, const double* di) {
  CellRay r{};
  for (int a = 0; a < 3; ++a) {
    r.o[a] = oi[a] + 0.5;
    r.d[a] = di[a];
    r.sgn[a] = di[a] > 0.0 ? 1 : (di[a] < 0.0 ? -1 : 0);
    r.inv[a] = r.sgn[a] != 0 ? 1.0 / di[a] : 0.0;
  }
  return r;
}

inline CellRay to_cell_ray(const IndexMap& map, const Ray& ray) {
  const std::array<double, 3> u = unit_direction(ray);
  double oi[3];
  double di[3];
  for (int a = 0; a < 3; ++a) {
    oi[a] = (ray.origin[static_cast<std::size_t>(a)] - map.translation[a]) * map.inv_scale[a];
    di[a] = u[static_cast<std::size_t>(a)] * map.inv_scale[a];
  }
  return cell_ray(oi, di);
}

/// Cell-space box of the active voxels: u ∈ [lo, hi).
struct CellBox {
  std::int64_t lo[3];
  std::int64_t hi[3];
  bool empty = true;
};

/// Slab test against the cell-space box [lo, hi) (as doubles); exact for zero direction
/// components (no division by them).
inline bool clip(const CellRay& r, const double* lo, const double* hi, double& t0, double& t1) {
  for (int a = 0; a < 3; ++a) {
    if (r.sgn[a] == 0) {
      if (!(r.o[a] >= lo[a] && r.o[a] < hi[a])) return false;
      continue;
    }
    double ta = (lo[a] - r.o[a]) * r.inv[a];
    double tb = (hi[a] - r.o[a]) * r.inv[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 < t1;
}

/// Slab test against the box.
inline bool clip(const CellRay& r, const CellBox& box, double& t0, double& t1) {
  if (box.empty) return false;
  double lo[3];
  double hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<double>(box.lo[a]);
    hi[a] = static_cast<double>(box.hi[a]);
  }
  return clip(r, lo, hi, t0, t1);
}

/// The distance where the ray leaves voxel c of axis a through its face (+∞ along the face).
inline double face_exit(const CellRay& r, int a, std::int64_t c) {
  return r.sgn[a] > 0   ? (static_cast<double>(c + 1) - r.o[a]) * r.inv[a]
         : r.sgn[a] < 0 ? (static_cast<double>(c) - r.o[a]) * r.inv[a]
                        : std::numeric_limits<double>::infinity();
}

/// ⌊p⌋: the cell entered at cell-space coordinate p going up (or along the axis), written with
/// integer truncation so a walk's start calls no libm (the same integer as std::floor for every
/// p a grid's index range holds).
inline std::int64_t cell_going_up(double p) {
  const auto i = static_cast<std::int64_t>(p);  // towards zero
  return static_cast<double>(i) > p ? i - 1 : i;
}
/// ⌈p⌉ − 1: the cell entered at p going down (std::ceil's integer, as above).
inline std::int64_t cell_going_down(double p) {
  const auto i = static_cast<std::int64_t>(p);  // towards zero
  return static_cast<double>(i) < p ? i : i - 1;
}
/// The cell containing the ray just after parameter t on axis a (the cell being entered).
inline std::int64_t cell_at(const CellRay& r, int a, double t) {
  const double p = r.o[a] + r.d[a] * t;
  return r.sgn[a] < 0 ? cell_going_down(p) : cell_going_up(p);
}

/// Where a walk stands: the ray, its box, the cell being entered at t, the end t1, and the
/// distances where the ray leaves that cell through its face on each axis.
struct WalkState {
  CellRay r{};
  CellBox box{};
  std::int64_t cell[3] = {0, 0, 0};
  double exit[3] = {0.0, 0.0, 0.0};
  double t = 0.0;
  double t1 = 0.0;
  std::int64_t budget = 0;
  bool done = true;

  /// Clips the ray `r` (set before) to the box over [t_begin, t_end] and finds the first cell;
  /// false (and done) when it misses.
  bool begin(const CellBox& b, double t_begin, double t_end) {
    box = b;
    done = true;
    double t0 = t_begin;
    t1 = t_end;
    if (!clip(r, box, t0, t1)) return false;
    for (int a = 0; a < 3; ++a) {
      cell[a] = cell_at(r, a, t0);
      if (r.sgn[a] != 0) cell[a] = std::clamp(cell[a], box.lo[a], box.hi[a] - 1);
    }
    // Safety net against rounding ping-pong; a correct march needs far fewer steps.
    budget = 8 * ((box.hi[0] - box.lo[0]) + (box.hi[1] - box.lo[1]) + (box.hi[2] - box.lo[2])) + 64;
    t = t0;
    done = false;
    for (int a = 0; a < 3; ++a) exit_face(a);
    return true;
  }
  /// The distance where the ray leaves `cell` through its face on axis a (+∞ along the face).
  void exit_face(int a) { exit[a] = face_exit(r, a, cell[a]); }
};

/// One voxel of the walk: the piece [t0, t1) of the voxel the walk was in (`produced` false
/// when rounding leaves it empty), then where the walk went.
struct VoxelStep {
  double t0 = 0.0;
  double t1 = 0.0;
  bool produced = false;
  bool ended = false;  ///< the piece reached the walk's end t1
  bool left = false;   ///< the step left the block [lo, hi)
};

/// The Amanatides–Woo step: the ray leaves voxel w.cell at the nearest of its three exit faces;
/// every axis whose face is crossed there moves (an edge or a corner moves several), so a ray
/// along a face line stays in the upper voxel (the half-open convention of dda.h). Only the
/// moved axes' exits are computed again (w.exit holds the others, the same numbers).
inline VoxelStep voxel_step(WalkState& w, const std::int64_t* lo, const std::int64_t* hi) {
  const double te = std::min(std::min(w.exit[0], w.exit[1]), w.exit[2]);
  VoxelStep s;
  s.t0 = w.t;
  s.t1 = std::min(te, w.t1);
  s.produced = s.t1 > w.t;
  if (s.produced) w.t = s.t1;
  if (te >= w.t1) {
    s.ended = true;
    return s;
  }
  for (int a = 0; a < 3; ++a) {
    if (w.exit[a] == te) {
      w.cell[a] += w.r.sgn[a];
      if (w.cell[a] < lo[a] || w.cell[a] >= hi[a]) s.left = true;
      w.exit_face(a);
    }
  }
  return s;
}

}  // namespace detail

/// @brief The one DDA stepping voxel by voxel through a dense box: the same pieces, bit for
/// bit, as the tree walk (Tracer::start/next) gives inside leaves, over every voxel of the box
/// (where the tree walk crosses an empty node or a tile at once, this walk gives its voxels one
/// by one), without a tree probe, an accessor or a copy per piece. For hot loops outside volume/
/// that hold a small grid's box as an array of records (docs/render.md §5b "Dense walk").
/// Immutable: one instance serves every thread.
class DenseWalk {
 public:
  DenseWalk() = default;
  /// Walks `box` (inclusive voxel indices, the array's extent) under `map` (dense_walk_map).
  DenseWalk(const detail::IndexMap& map, const IndexBox& box);

  /// Calls visit(t0, t1, index) for each piece of `ray` over [tmin, tmax] inside the box, in
  /// order of increasing t: [t0, t1) in world distance inside the voxel at `index` of the dense
  /// box (x-major, as volume::to_dense lays it out); visit returns false to stop. Throws
  /// weft::Error for a bad ray or range (as Tracer::start does).
  ///
  /// The step is voxel_step's (the axes whose exit face_exit is the least move; the same clip,
  /// first cell and exit arithmetic), kept in the array's terms: the record index moves by a
  /// stride, each axis counts the voxels left before the box's face, and each exit is computed
  /// from the face's coordinate kept as a double (the same integer face_exit converts, so the
  /// same number). Each step moves at least one axis towards its face, so the walk ends
  /// without voxel_step's safety budget.
  template <typename Visit>
  void march(const Ray& ray, double tmin, double tmax, Visit&& visit) const {
    State state;
    march(ray, tmin, tmax, state, visit);
  }

  /// Where a walk stands between its steps: the ray and, per axis, the face it leaves through
  /// next and where. The caller holds it (a per-thread medium keeps one): then a call inside
  /// `visit` (the hazard's log1p) finds these numbers in memory, instead of the compiler
  /// saving and restoring a dozen registers around every call (docs/render.md §6 "Coarse
  /// grids").
  struct State {
    detail::CellRay r{};
    double face[3] = {0.0, 0.0, 0.0};  ///< cell-space coordinate of the face each axis leaves through next
    double exit[3] = {0.0, 0.0, 0.0};  ///< the distance where the ray reaches that face
  };

  /// march() with the walk's state in `state` (its contents on entry do not matter).
  template <typename Visit>
  void march(const Ray& ray, double tmin, double tmax, State& state, Visit&& visit) const {
    detail::CellRay& r = state.r;
    double* face = state.face;
    double* exit = state.exit;
    r = cell_ray(ray, tmin, tmax);
    double t = tmin;
    double t1 = tmax;
    if (empty_ || !detail::clip(r, lo_, hi_, t, t1)) return;
    std::int64_t index = 0;
    std::int64_t room[3];    // voxels left on each axis before the walk leaves the box
    std::int64_t stride[3];  // the index's move per step on each axis
    // The first cell (detail::cell_at, clamped into the box along a moving axis) and what the
    // walk keeps per axis, the direction's sign tested once per axis.
    for (int a = 0; a < 3; ++a) {
      const double p = r.o[a] + r.d[a] * t;
      std::int64_t c = 0;
      if (r.sgn[a] > 0) {
        c = std::clamp(detail::cell_going_up(p), box_lo_[a], box_hi_[a] - 1);
        room[a] = box_hi_[a] - 1 - c;
        stride[a] = stride_[a];
        face[a] = static_cast<double>(c + 1);
        exit[a] = (face[a] - r.o[a]) * r.inv[a];
      } else if (r.sgn[a] < 0) {
        c = std::clamp(detail::cell_going_down(p), box_lo_[a], box_hi_[a] - 1);
        room[a] = c - box_lo_[a];
        stride[a] = -stride_[a];
        face[a] = static_cast<double>(c);
        exit[a] = (face[a] - r.o[a]) * r.inv[a];
      } else {
        c = detail::cell_going_up(p);
        room[a] = 0;  // never moves
        stride[a] = 0;
        face[a] = static_cast<double>(c);
        exit[a] = std::numeric_limits<double>::infinity();
      }
      index += (c - box_lo_[a]) * stride_[a];
    }
    for (;;) {
      const double te = std::min(std::min(exit[0], exit[1]), exit[2]);
      const double end = std::min(te, t1);
      if (end > t) {
        if (!visit(t, end, index)) return;
        t = end;
      }
      if (te >= t1) return;
      for (int a = 0; a < 3; ++a) {
        // te is the least exit, so exit ≤ te means exit == te, in one comparison.
        if (!(exit[a] <= te)) continue;
        if (--room[a] < 0) return;
        index += stride[a];
        face[a] += static_cast<double>(r.sgn[a]);
        exit[a] = (face[a] - r.o[a]) * r.inv[a];
      }
    }
  }

 private:
  /// The checked cell-space ray (throws for a bad ray or range).
  [[nodiscard]] detail::CellRay cell_ray(const Ray& ray, double tmin, double tmax) const {
    if (std::isnan(tmin) || std::isnan(tmax)) detail::fail_bad_ray(ray, tmin, tmax);
    return detail::to_cell_ray(map_, ray);
  }

  detail::IndexMap map_{};
  bool empty_ = true;
  double lo_[3] = {0.0, 0.0, 0.0};  ///< the box in cell space, [lo, hi)
  double hi_[3] = {0.0, 0.0, 0.0};
  std::int64_t box_lo_[3] = {0, 0, 0};
  std::int64_t box_hi_[3] = {0, 0, 0};
  std::int64_t stride_[3] = {0, 0, 0};  ///< x-major: ny·nz, nz, 1
};

/// The world → index map a Tracer of `grid` applies, for a DenseWalk; false when the grid's
/// map is not scale-translate (then only the tree walk applies).
[[nodiscard]] bool dense_walk_map(const Grid& grid, detail::IndexMap& map);

}  // namespace weft::volume
