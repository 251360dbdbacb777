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
#include "weft/volume/voxel_walk.h"

namespace weft::volume::detail {

using FloatTree = openvdb::FloatTree;
using LeafT = FloatTree::LeafNodeType;
using Accessor = openvdb::FloatGrid::ConstAccessor;

/// A grid's world → index map, read once per tracer: the transform's virtual map behind a
/// shared pointer costs a pointer copy and two virtual calls per ray otherwise. Scale-translate
/// maps (every grid weft writes) are applied by IndexMap (voxel_walk.h) with the map's own
/// arithmetic, bit for bit; any other map is asked.
struct CellMap {
  openvdb::math::MapBase::ConstPtr map;
  bool scale_translate = false;
  IndexMap index;
  explicit CellMap(const openvdb::FloatGrid& grid) : map(grid.transform().baseMap()) {
    if (map->isType<openvdb::math::ScaleTranslateMap>() || map->isType<openvdb::math::UniformScaleTranslateMap>()) {
      const auto& st = static_cast<const openvdb::math::ScaleTranslateMap&>(*map);
      scale_translate = true;
      for (int a = 0; a < 3; ++a) {
        index.translation[a] = st.getTranslation()[a];
        index.inv_scale[a] = st.getInvScale()[a];
      }
    }
  }
};

inline CellRay to_cell_ray(const CellMap& map, const Ray& ray) {
  if (map.scale_translate) return to_cell_ray(map.index, ray);
  const std::array<double, 3> u = unit_direction(ray);
  const openvdb::Vec3d oi = map.map->applyInverseMap(openvdb::Vec3d(ray.origin[0], ray.origin[1], ray.origin[2]));
  const openvdb::Vec3d di = map.map->applyInverseJacobian(openvdb::Vec3d(u[0], u[1], u[2]));
  return cell_ray(oi.asPointer(), di.asPointer());
}

inline CellRay to_cell_ray(const openvdb::FloatGrid& grid, const Ray& ray) { return to_cell_ray(CellMap(grid), ray); }

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
///
/// The ray and the box may be given relative to a voxel `base` (cell space minus base): the
/// walk's arithmetic is then on small numbers, the same whatever the grid's index origin, and
/// only the tree's lookups and the pieces' voxels add base back (a beam walks relative to its
/// box's corner, docs/validate.md "Beams far from index 0").
struct CellWalk : WalkState {
  std::int64_t base[3] = {0, 0, 0};
  // The leaf being walked (null: probe the tree at `cell` next) and its voxels [leaf_lo, leaf_hi).
  const LeafT* leaf = nullptr;
  std::int64_t leaf_lo[3] = {0, 0, 0};
  std::int64_t leaf_hi[3] = {0, 0, 0};
  const float* data = nullptr;
  const LeafT::NodeMaskType* mask = nullptr;

  /// Begins a walk of `ray` over [t_begin, t_end]; false (and no pieces) when it misses the box.
  /// `shift` (null: 0) is the base the ray and the box are relative to.
  bool start(const CellRay& ray, const CellBox& b, double t_begin, double t_end, const std::int64_t* shift = nullptr) {
    leaf = nullptr;
    r = ray;
    for (int a = 0; a < 3; ++a) base[a] = shift != nullptr ? shift[a] : 0;
    return begin(b, t_begin, t_end);
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
        const openvdb::Coord c(static_cast<openvdb::Int32>(cell[0] + base[0]),
                               static_cast<openvdb::Int32>(cell[1] + base[1]),
                               static_cast<openvdb::Int32>(cell[2] + base[2]));
        leaf = acc.probeConstLeaf(c);
        if (leaf != nullptr) {
          const openvdb::Coord org = leaf->origin();
          for (int a = 0; a < 3; ++a) {
            leaf_lo[a] = org[a] - base[a];
            leaf_hi[a] = leaf_lo[a] + static_cast<std::int64_t>(LeafT::DIM);
          }
          data = leaf->buffer().data();
          mask = &leaf->getValueMask();
          for (int a = 0; a < 3; ++a) exit_face(a);
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
            // Aligned in the tree's own (absolute) indices.
            blo[a] = ((cell[a] + base[a]) & ~(size - 1)) - base[a];
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
            for (int a = 0; a < 3; ++a) s.lo[a] = blo[a] + base[a];
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
      // Voxel by voxel inside the leaf: the step shared with the dense walk (voxel_walk.h).
      const openvdb::Index off = LeafT::coordToOffset(openvdb::Coord(static_cast<openvdb::Int32>(cell[0] + base[0]),
                                                                     static_cast<openvdb::Int32>(cell[1] + base[1]),
                                                                     static_cast<openvdb::Int32>(cell[2] + base[2])));
      const std::int64_t voxel[3] = {cell[0] + base[0], cell[1] + base[1], cell[2] + base[2]};
      const VoxelStep step = voxel_step(*this, leaf_lo, leaf_hi);
      if (step.produced) {
        s.t0 = step.t0;
        s.t1 = step.t1;
        s.value = mask->isOn(off) ? data[off] : 0.0f;
        for (int a = 0; a < 3; ++a) s.lo[a] = voxel[a];
        s.size = 1;
      }
      if (step.ended) {
        done = true;
        return step.produced;
      }
      if (step.left) {
        leaf = nullptr;
      } else if (--budget <= 0) {
        done = true;
      }
      if (step.produced) return true;
    }
    return false;
  }
};

/// The walk of CellWalk over [t0, t1] (world distances) with a callback:
/// `visit(t0, t1, value, lowest voxel, size)` returns false to stop. `base` (null: 0): the voxel
/// the ray and the box are relative to (CellWalk).
template <typename Visit>
void march_cells(Accessor& acc, const CellRay& r, const CellBox& box, double t0, double t1, Visit&& visit,
                 const std::int64_t* base = nullptr) {
  CellWalk walk;
  if (!walk.start(r, box, t0, t1, base)) return;
  CellStep s;
  while (walk.next(acc, s))
    if (!visit(s.t0, s.t1, s.value, static_cast<const std::int64_t*>(s.lo), s.size)) return;
}

}  // namespace weft::volume::detail
