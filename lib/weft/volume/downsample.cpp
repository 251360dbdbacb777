#include "weft/volume/downsample.h"

#include "weft/core/error.h"
#include "weft/volume/block_lattice.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
Grid downsample(const Grid& fine, int factor) {
  if (factor < 1 || factor > 4096) fail("downsample: factor must be in 1..4096, got {}", factor);
  if (fine.active_voxel_count() == 0) fail("downsample: grid '{}' has no active voxels", fine.name());
  ensure_openvdb_initialized();
  const auto& src = *fine.impl().grid;
  const BlockLattice lattice = block_lattice(fine.active_bbox(), factor);
  const auto block_of = [&](const openvdb::Coord& c) {
    return openvdb::Coord(static_cast<int>(lattice.block_of(0, c.x())), static_cast<int>(lattice.block_of(1, c.y())),
                          static_cast<int>(lattice.block_of(2, c.z())));
  };
  // Sums per coarse voxel in double: leaves first (the bulk), then active tiles voxel by voxel
  // of their overlap with each block. The iteration order of a tree is fixed, so is the sum.
  openvdb::DoubleGrid sums(0.0);
  auto acc = sums.getAccessor();
  const auto add = [&](const openvdb::Coord& c, double v) {
    const openvdb::Coord cc = block_of(c);
    acc.setValueOn(cc, acc.getValue(cc) + v);
  };
  for (auto leaf = src.tree().cbeginLeaf(); leaf; ++leaf) {
    const float* data = leaf->buffer().data();
    const openvdb::Coord o = leaf->origin();
    for (auto on = leaf->getValueMask().beginOn(); on; ++on) {
      add(o + openvdb::FloatTree::LeafNodeType::offsetToLocalCoord(on.pos()), static_cast<double>(data[on.pos()]));
    }
  }
  auto tiles = src.tree().cbeginValueOn();
  tiles.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; tiles; ++tiles) {
    if (tiles.isVoxelValue()) continue;
    openvdb::CoordBBox b;
    tiles.getBoundingBox(b);
    const double v = static_cast<double>(*tiles);
    const openvdb::Coord lo_block = block_of(b.min());
    const openvdb::Coord hi_block = block_of(b.max());
    for (int i = lo_block.x(); i <= hi_block.x(); ++i) {
      for (int j = lo_block.y(); j <= hi_block.y(); ++j) {
        for (int k = lo_block.z(); k <= hi_block.z(); ++k) {
          const openvdb::Coord lo(static_cast<int>(lattice.first_voxel(0, i)),
                                  static_cast<int>(lattice.first_voxel(1, j)),
                                  static_cast<int>(lattice.first_voxel(2, k)));
          const openvdb::CoordBBox block(lo, lo.offsetBy(factor - 1));
          openvdb::CoordBBox overlap = b;
          overlap.intersect(block);
          acc.setValueOn(openvdb::Coord(i, j, k),
                         acc.getValue(openvdb::Coord(i, j, k)) + v * static_cast<double>(overlap.volume()));
        }
      }
    }
  }
  const double cells = static_cast<double>(factor) * static_cast<double>(factor) * static_cast<double>(factor);
  Grid coarse(fine.voxel_size() * factor, fine.name());
  coarse.set_origin(lattice.coarse_origin(fine.origin(), fine.voxel_size()));
  for (const auto& [k, v] : fine.metadata()) {
    if (k.rfind("weft:", 0) == 0) coarse.set_metadata(k, v);
  }
  coarse.set_metadata("weft:downsample_factor", std::to_string(factor));
  auto& dst = *coarse.impl().grid;
  auto out = dst.getAccessor();
  for (auto it = sums.cbeginValueOn(); it; ++it) out.setValueOn(it.getCoord(), static_cast<float>(*it / cells));
  return coarse;
}

}  // namespace weft::volume
