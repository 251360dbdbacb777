#include "weft/volume/downsample.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/volume/block_lattice.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

/// Σ of `fine`'s values per block of `lattice`, in double: leaves first (the bulk), then active
/// tiles voxel by voxel of their overlap with each block. The iteration order of a tree is
/// fixed, so is the sum. A block is active when any of its fine voxels is.
openvdb::DoubleGrid::Ptr block_sums(const Grid& fine, const BlockLattice& lattice) {
  ensure_openvdb_initialized();
  const int factor = lattice.factor;
  const auto& src = *fine.impl().grid;
  const auto block_of = [&](const openvdb::Coord& c) {
    return openvdb::Coord(static_cast<int>(lattice.block_of(0, c.x())), static_cast<int>(lattice.block_of(1, c.y())),
                          static_cast<int>(lattice.block_of(2, c.z())));
  };
  auto sums = openvdb::DoubleGrid::create(0.0);
  auto acc = sums->getAccessor();
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
  return sums;
}

double block_volume(int factor) {
  return static_cast<double>(factor) * static_cast<double>(factor) * static_cast<double>(factor);
}

}  // namespace

Grid downsample(const Grid& fine, int factor) {
  if (factor < 1 || factor > 4096) fail("downsample: factor must be in 1..4096, got {}", factor);
  if (fine.active_voxel_count() == 0) fail("downsample: grid '{}' has no active voxels", fine.name());
  const BlockLattice lattice = block_lattice(fine.active_bbox(), factor);
  const openvdb::DoubleGrid::Ptr sums = block_sums(fine, lattice);
  const double cells = block_volume(factor);
  Grid coarse(fine.voxel_size() * factor, fine.name());
  coarse.set_origin(lattice.coarse_origin(fine.origin(), fine.voxel_size()));
  for (const auto& [k, v] : fine.metadata()) {
    if (k.rfind("weft:", 0) == 0) coarse.set_metadata(k, v);
  }
  coarse.set_metadata("weft:downsample_factor", std::to_string(factor));
  auto& dst = *coarse.impl().grid;
  auto out = dst.getAccessor();
  for (auto it = sums->cbeginValueOn(); it; ++it) out.setValueOn(it.getCoord(), static_cast<float>(*it / cells));
  return coarse;
}

std::optional<BlockMeanMismatch> block_mean_mismatch(const Grid& coarse, const Grid& fine) {
  const double h = fine.voxel_size();
  const double H = coarse.voxel_size();
  const auto factor = static_cast<int>(std::lround(H / h));
  if (factor < 1 || factor > 4096) fail("block means: cells of {:.6g} are not 1..4096 voxels of {:.6g}", H, h);
  const auto of = coarse.origin();
  const auto og = fine.origin();
  BlockLattice lattice{{0, 0, 0}, factor};
  for (std::size_t a = 0; a < 3; ++a) lattice.anchor[a] = static_cast<int>(std::lround((of[a] - og[a]) / h));
  const openvdb::DoubleGrid::Ptr sums = block_sums(fine, lattice);
  const double cells = block_volume(factor);
  // Relative 1e-3: far above the rounding of a mean stored as a float (or a half) from sums taken
  // in another order, far below what another cloth's voxels change.
  constexpr double kTolerance = 1e-3;
  const auto differ = [](double a, double b) {
    return std::abs(a - b) > kTolerance * std::max(std::abs(a), std::abs(b));
  };
  const auto at = [&](const openvdb::Coord& c, float stored, double mean) {
    const std::array<int, 3> i{c.x(), c.y(), c.z()};
    return BlockMeanMismatch{
        i, {of[0] + H * (i[0] + 0.5), of[1] + H * (i[1] + 0.5), of[2] + H * (i[2] + 0.5)}, stored, mean};
  };
  const auto& tree = coarse.impl().grid->tree();
  auto stored = coarse.impl().grid->getConstAccessor();
  for (auto it = sums->cbeginValueOn(); it; ++it) {
    const double mean = *it / cells;
    const float value = stored.getValue(it.getCoord());
    if (differ(value, mean)) return at(it.getCoord(), value, mean);
  }
  auto sum = sums->getConstAccessor();
  for (auto it = tree.cbeginValueOn(); it; ++it) {
    // A tile stands for many cells: its first cell speaks for them (a fine block inside it that
    // differs is found by the loop above when active, and here as an inactive one otherwise).
    const double mean = sum.getValue(it.getCoord()) / cells;
    if (differ(*it, mean)) return at(it.getCoord(), *it, mean);
  }
  return std::nullopt;
}

}  // namespace weft::volume
