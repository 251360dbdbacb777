#pragma once
/// @file
/// @brief The OpenVDB side of weft::volume::Grid. Include only from .cpp files.

#include <openvdb/openvdb.h>

#include "weft/volume/grid.h"

namespace weft::volume {

struct Grid::Impl {
  openvdb::FloatGrid::Ptr grid;
};

/// Wraps an existing OpenVDB grid (shares it); checks it has a uniform-scale transform.
Grid make_grid(std::shared_ptr<Grid::Impl> impl);
Grid wrap_openvdb(openvdb::FloatGrid::Ptr grid);
/// A deep copy of the grid's tree and metadata with the grid's own transform (OpenVDB's deepCopy
/// recomputes the voxel size from the transform, which rounds it for an origin far from 0).
openvdb::FloatGrid::Ptr deep_copy(const Grid& grid);

/// @brief Voxel reads by index through an accessor that keep the last leaf's buffer and mask:
/// a ray's reads come leaf after leaf, so most skip the accessor's own cache check and node
/// probing (the trackers' point lookups, VoxelReader). Values are the voxel's or its tile's,
/// 0 where inactive. One per thread.
struct LeafCachedReader {
  using LeafT = openvdb::FloatTree::LeafNodeType;
  openvdb::FloatGrid::ConstAccessor acc;
  openvdb::Coord leaf_origin{openvdb::Coord::max()};  // never a leaf's origin (those are multiples of 8)
  const float* data = nullptr;
  const LeafT::NodeMaskType* mask = nullptr;
  explicit LeafCachedReader(const openvdb::FloatGrid& grid) : acc(grid.getConstAccessor()) {}
  float value(const openvdb::Coord& c) {
    constexpr openvdb::Int32 kMask = ~static_cast<openvdb::Int32>(LeafT::DIM - 1);
    const openvdb::Coord org(c.x() & kMask, c.y() & kMask, c.z() & kMask);
    if (org != leaf_origin) {
      const LeafT* leaf = acc.probeConstLeaf(c);
      if (leaf == nullptr) {  // a tile or empty space: no buffer to keep
        leaf_origin = openvdb::Coord::max();
        float v = 0.0F;
        return acc.probeValue(c, v) ? v : 0.0F;
      }
      leaf_origin = org;
      data = leaf->buffer().data();
      mask = &leaf->getValueMask();
    }
    const openvdb::Index off = LeafT::coordToOffset(c);
    return mask->isOn(off) ? data[off] : 0.0F;
  }
};

/// The bounding box of the active voxels (and active tiles), as
/// openvdb::FloatGrid::evalActiveVoxelBoundingBox gives it, with the leaves visited on all
/// threads (a union of boxes: the same box for any thread count). Empty when nothing is active.
openvdb::CoordBBox active_voxel_bbox(const openvdb::FloatGrid& grid);

/// Throws weft::Error naming `path` and the grid when Grid::load would refuse a file of `grid`
/// for what the writing does or for the grid's frame: a finite value that a grid flagged
/// saveFloatAsHalf stores as ±∞ (beyond 65504; the voxel and the value are named), a background
/// other than 0, a transform other than cubic voxels, an active voxel beyond kMaxIndex. The values
/// held are the writer's (local fields' α is +∞ where a variance is 0). Every writer of grids
/// calls it before writing anything.
void require_writable(const openvdb::FloatGrid& grid, const std::string& path);

/// Calls openvdb::initialize() once per process.
void ensure_openvdb_initialized();

}  // namespace weft::volume
