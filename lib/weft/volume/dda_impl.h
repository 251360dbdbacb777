#pragma once
/// @file
/// @brief The DDA kernel, templated on the visitor so hot loops inline it. Include only from
/// .cpp files of lib/weft/volume (it includes OpenVDB).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <openvdb/openvdb.h>

#include "weft/core/error.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume::detail {

using FloatTree = openvdb::FloatTree;
using LeafT = FloatTree::LeafNodeType;
using Accessor = openvdb::FloatGrid::ConstAccessor;

/// A ray in "cell space" u = index + ½, where voxel i covers u ∈ [i, i+1): the half-open
/// convention makes face, edge and corner cases a matter of floor().
struct CellRay {
  double o[3];
  double d[3];    ///< cell-space displacement per world unit of t
  double inv[3];  ///< 1/d, unused where sgn = 0
  int sgn[3];     ///< −1, 0, +1; −0.0 counts as 0
};

/// A grid's world → index map, read once per tracer: the transform's virtual map behind a
/// shared pointer costs a pointer copy and two virtual calls per ray otherwise. Scale-translate
/// maps (every grid weft writes) are applied here with the map's own arithmetic, bit for bit
/// (openvdb ScaleTranslateMap::applyInverseMap / applyInverseJacobian); any other map is asked.
struct CellMap {
  openvdb::math::MapBase::ConstPtr map;
  bool scale_translate = false;
  openvdb::Vec3d translation{0.0};
  openvdb::Vec3d inv_scale{1.0};
  explicit CellMap(const openvdb::FloatGrid& grid) : map(grid.transform().baseMap()) {
    if (map->isType<openvdb::math::ScaleTranslateMap>() || map->isType<openvdb::math::UniformScaleTranslateMap>()) {
      const auto& st = static_cast<const openvdb::math::ScaleTranslateMap&>(*map);
      scale_translate = true;
      translation = st.getTranslation();
      inv_scale = st.getInvScale();
    }
  }
  [[nodiscard]] openvdb::Vec3d to_index(const openvdb::Vec3d& p) const {
    if (!scale_translate) return map->applyInverseMap(p);
    return {(p.x() - translation.x()) * inv_scale.x(), (p.y() - translation.y()) * inv_scale.y(),
            (p.z() - translation.z()) * inv_scale.z()};
  }
  [[nodiscard]] openvdb::Vec3d to_index_direction(const openvdb::Vec3d& d) const {
    if (!scale_translate) return map->applyInverseJacobian(d);
    return d * inv_scale;
  }
};

inline CellRay to_cell_ray(const CellMap& map, const Ray& ray) {
  const auto& o = ray.origin;
  const auto& d = ray.direction;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(o[a])) fail("ray: origin component {} is {}", a, o[a]);
    if (!std::isfinite(d[a])) fail("ray: direction component {} is {}", a, d[a]);
  }
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(len > 0.0) || !std::isfinite(len)) fail("ray: direction ({}, {}, {}) has no length", d[0], d[1], d[2]);
  const openvdb::Vec3d oi = map.to_index(openvdb::Vec3d(o[0], o[1], o[2]));
  const openvdb::Vec3d di = map.to_index_direction(openvdb::Vec3d(d[0] / len, d[1] / len, d[2] / len));
  CellRay r{};
  for (int a = 0; a < 3; ++a) {
    r.o[a] = oi[a] + 0.5;
    r.d[a] = di[a];
    r.sgn[a] = di[a] > 0.0 ? 1 : (di[a] < 0.0 ? -1 : 0);
    r.inv[a] = r.sgn[a] != 0 ? 1.0 / di[a] : 0.0;
  }
  return r;
}

inline CellRay to_cell_ray(const openvdb::FloatGrid& grid, const Ray& ray) { return to_cell_ray(CellMap(grid), ray); }

/// Cell-space box of the active voxels: u ∈ [lo, hi).
struct CellBox {
  std::int64_t lo[3];
  std::int64_t hi[3];
  bool empty = true;
};

inline CellBox active_cell_box(const openvdb::FloatGrid& grid) {
  CellBox box{};
  if (grid.activeVoxelCount() == 0) return box;
  const openvdb::CoordBBox b = active_voxel_bbox(grid);
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = b.min()[a];
    box.hi[a] = std::int64_t{b.max()[a]} + 1;
  }
  box.empty = false;
  return box;
}

/// Slab test against the box; exact for zero direction components (no division by them).
inline bool clip(const CellRay& r, const CellBox& box, double& t0, double& t1) {
  if (box.empty) return false;
  for (int a = 0; a < 3; ++a) {
    const auto lo = static_cast<double>(box.lo[a]);
    const auto hi = static_cast<double>(box.hi[a]);
    if (r.sgn[a] == 0) {
      if (!(r.o[a] >= lo && r.o[a] < hi)) return false;
      continue;
    }
    double ta = (lo - r.o[a]) * r.inv[a];
    double tb = (hi - r.o[a]) * r.inv[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 < t1;
}

/// The cell containing the ray just after parameter t on axis a (the cell being entered).
inline std::int64_t cell_at(const CellRay& r, int a, double t) {
  const double p = r.o[a] + r.d[a] * t;
  if (r.sgn[a] < 0) return static_cast<std::int64_t>(std::ceil(p)) - 1;
  return static_cast<std::int64_t>(std::floor(p));
}

/// One piece of a walk: [t0, t1) in world distance inside a cell of `size`³ voxels whose
/// lowest voxel is `lo` (size 1: a voxel of a leaf; 8, 128, 4096: a tile or empty node).
struct CellStep {
  double t0 = 0.0;
  double t1 = 0.0;
  float value = 0.0f;
  std::int64_t lo[3] = {0, 0, 0};
  int size = 1;
};

/// Amanatides–Woo traversal with hierarchical skipping, as a resumable state (the one DDA of
/// weft): `start` clips the ray to the box, each `next` yields the following cell piece in
/// order of increasing t, so the pieces tile [t0, t1] ∩ box without gaps. Inside a leaf it steps
/// voxel by voxel reading the leaf's buffer directly; elsewhere it crosses a whole tile or empty
/// node (getValueDepth) at once. Callers either pull pieces (Tracer::start/next, for code
/// outside volume/ that cannot take a template through the header wall) or are called back
/// (march_cells, inlined for volume's own hot loops). Inactive voxels have value 0.
struct CellWalk {
  CellRay r{};
  CellBox box{};
  std::int64_t cell[3] = {0, 0, 0};
  double t = 0.0;
  double t1 = 0.0;
  std::int64_t budget = 0;
  // The leaf being walked (null: probe the tree at `cell` next).
  const LeafT* leaf = nullptr;
  openvdb::Coord org;
  const float* data = nullptr;
  const LeafT::NodeMaskType* mask = nullptr;
  bool done = true;

  /// Begins a walk of `ray` over [t_begin, t_end]; false (and no pieces) when it misses the box.
  bool start(const CellRay& ray, const CellBox& b, double t_begin, double t_end) {
    r = ray;
    box = b;
    leaf = nullptr;
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
    return true;
  }

  /// The next piece, or false when the walk has ended.
  bool next(Accessor& acc, CellStep& s) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    while (!done) {
      if (leaf == nullptr) {
        if (!(t < t1) || budget-- <= 0) {
          done = true;
          return false;
        }
        const openvdb::Coord c(static_cast<openvdb::Int32>(cell[0]), static_cast<openvdb::Int32>(cell[1]),
                               static_cast<openvdb::Int32>(cell[2]));
        leaf = acc.probeConstLeaf(c);
        if (leaf != nullptr) {
          org = leaf->origin();
          data = leaf->buffer().data();
          mask = &leaf->getValueMask();
        } else {
          // A tile or empty space: constant over a block of `size`³ voxels aligned to `size`.
          const int depth = acc.getValueDepth(c);
          std::int64_t size = 0;
          if (depth >= 2) {
            size = LeafT::DIM;
          } else if (depth == 1) {
            size = FloatTree::RootNodeType::ChildNodeType::ChildNodeType::DIM;
          } else {
            size = FloatTree::RootNodeType::ChildNodeType::DIM;
          }
          float v = 0.0f;
          if (!acc.probeValue(c, v)) v = 0.0f;
          std::int64_t blo[3];
          double tn[3];
          double te = kInf;
          for (int a = 0; a < 3; ++a) {
            blo[a] = cell[a] & ~(size - 1);
            tn[a] = r.sgn[a] > 0   ? (static_cast<double>(blo[a] + size) - r.o[a]) * r.inv[a]
                    : r.sgn[a] < 0 ? (static_cast<double>(blo[a]) - r.o[a]) * r.inv[a]
                                   : kInf;
            te = std::min(te, tn[a]);
          }
          const double tend = std::min(te, t1);
          const bool produced = tend > t;
          if (produced) {
            s.t0 = t;
            s.t1 = tend;
            s.value = v;
            for (int a = 0; a < 3; ++a) s.lo[a] = blo[a];
            s.size = static_cast<int>(size);
            t = tend;
          }
          if (te >= t1) {
            done = true;
            return produced;
          }
          for (int a = 0; a < 3; ++a) {
            if (r.sgn[a] == 0) continue;
            if (tn[a] == te) {
              cell[a] = r.sgn[a] > 0 ? blo[a] + size : blo[a] - 1;
            } else {
              cell[a] = std::clamp(cell_at(r, a, te), blo[a], blo[a] + size - 1);
            }
          }
          if (produced) return true;
          continue;
        }
      }
      // Voxel by voxel inside the leaf.
      double tn[3];
      double te = kInf;
      for (int a = 0; a < 3; ++a) {
        tn[a] = r.sgn[a] > 0   ? (static_cast<double>(cell[a] + 1) - r.o[a]) * r.inv[a]
                : r.sgn[a] < 0 ? (static_cast<double>(cell[a]) - r.o[a]) * r.inv[a]
                               : kInf;
        te = std::min(te, tn[a]);
      }
      const double tend = std::min(te, t1);
      const bool produced = tend > t;
      if (produced) {
        const openvdb::Index off = LeafT::coordToOffset(openvdb::Coord(static_cast<openvdb::Int32>(cell[0]),
                                                                       static_cast<openvdb::Int32>(cell[1]),
                                                                       static_cast<openvdb::Int32>(cell[2])));
        s.t0 = t;
        s.t1 = tend;
        s.value = mask->isOn(off) ? data[off] : 0.0f;
        for (int a = 0; a < 3; ++a) s.lo[a] = cell[a];
        s.size = 1;
        t = tend;
      }
      if (te >= t1) {
        done = true;
        return produced;
      }
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        if (tn[a] == te) {
          cell[a] += r.sgn[a];
          if (cell[a] < org[a] || cell[a] >= org[a] + static_cast<std::int64_t>(LeafT::DIM)) inside = false;
        }
      }
      if (!inside) {
        leaf = nullptr;
      } else if (--budget <= 0) {
        done = true;
      }
      if (produced) return true;
    }
    return false;
  }
};

/// The walk of CellWalk over [t0, t1] (world distances) with a callback:
/// `visit(t0, t1, value, lowest voxel, size)` returns false to stop.
template <typename Visit>
void march_cells(Accessor& acc, const CellRay& r, const CellBox& box, double t0, double t1, Visit&& visit) {
  CellWalk walk;
  if (!walk.start(r, box, t0, t1)) return;
  CellStep s;
  while (walk.next(acc, s))
    if (!visit(s.t0, s.t1, s.value, static_cast<const std::int64_t*>(s.lo), s.size)) return;
}

}  // namespace weft::volume::detail
