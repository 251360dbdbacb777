// Local gamma statistics per block of B³ voxels, as coarse grids for rendering (docs/architecture.md §6).
//
// Blocks are built from the grid's own leaves and tiles, never from a dense B³ copy: the cost is
// the active voxels (each visited once per block it lies in, i.e. once) plus, per block, its
// non-empty columns. That keeps memory bounded for any block size; what is left is estimated from
// the leaves before anything is spent (local_fields.h).
#include "weft/fit/local_fields.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>

#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/core/parallel.h"
#include "weft/transmittance/shape_rate.h"
#include "weft/volume/block_lattice.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::fit {
namespace {

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;
using Key = std::array<std::int64_t, 3>;

// Blocks up to this edge accumulate their columns in a dense B² array per axis (≤ 96 KiB per
// thread); larger blocks keep only the columns that hold data.
constexpr int kDenseBlock = 64;
constexpr std::uint64_t kLeafBytes = 512 * 4 + 64 + 96;  // an 8³ float leaf: values, mask, node
constexpr std::uint64_t kColumnBytes = 48;               // a hash-map column: key, sum, node, bucket

// A leaf (with its active bounding box) or an active tile (box and value) of the input tree.
struct Item {
  const Leaf* leaf = nullptr;
  openvdb::CoordBBox box;
  float value = 0.0f;
};

struct Entry {
  Key block;
  std::uint32_t item;
  bool operator<(const Entry& o) const { return block != o.block ? block < o.block : item < o.item; }
};

struct BlockResult {
  Key key{};
  double mean = 0.0;
  std::array<double, 3> variance{};
};

std::vector<Item> tree_items(const openvdb::FloatGrid& vdb) {
  std::vector<Item> items;
  for (auto it = vdb.tree().cbeginLeaf(); it; ++it) {
    Item item;
    item.leaf = it.getLeaf();
    if (item.leaf->isEmpty()) continue;  // no active voxel
    item.box = openvdb::CoordBBox();     // empty: the call below grows it to the active voxels
    item.leaf->evalActiveBoundingBox(item.box, false);
    items.push_back(item);
  }
  // Active tiles above the leaf level stand for a box of voxels with one value.
  auto tile = vdb.tree().cbeginValueOn();
  tile.setMaxDepth(Tree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; tile; ++tile) {
    if (tile.isVoxelValue()) continue;
    Item item;
    tile.getBoundingBox(item.box);
    item.value = *tile;
    items.push_back(item);
  }
  return items;
}

std::array<std::int64_t, 6> block_range(const openvdb::CoordBBox& box, const volume::BlockLattice& lattice) {
  return {lattice.block_of(0, box.min().x()), lattice.block_of(1, box.min().y()), lattice.block_of(2, box.min().z()),
          lattice.block_of(0, box.max().x()), lattice.block_of(1, box.max().y()), lattice.block_of(2, box.max().z())};
}

std::uint64_t range_count(const std::array<std::int64_t, 6>& r) {
  return static_cast<std::uint64_t>((r[3] - r[0] + 1) * (r[4] - r[1] + 1) * (r[5] - r[2] + 1));
}

// Column sums of one block per axis: column (p, q) of axis a is indexed by the in-block
// coordinates of the two other axes in increasing axis order.
class Columns {
 public:
  explicit Columns(int block) : b_(block), dense_(block <= kDenseBlock) {
    if (dense_) {
      for (auto& c : dense_sums_) c.assign(static_cast<std::size_t>(b_) * static_cast<std::size_t>(b_), 0.0);
    }
  }
  void reset() {
    for (int a = 0; a < 3; ++a) {
      if (dense_) {
        std::fill(dense_sums_[a].begin(), dense_sums_[a].end(), 0.0);
      } else {
        index_[a].clear();
        sparse_sums_[a].clear();
      }
    }
  }
  void add(int axis, std::int64_t p, std::int64_t q, double v) {
    const auto c = static_cast<std::uint64_t>(p * b_ + q);
    auto a = static_cast<std::size_t>(axis);
    if (dense_) {
      dense_sums_[a][c] += v;
      return;
    }
    const auto [it, inserted] = index_[a].try_emplace(c, sparse_sums_[a].size());
    if (inserted) sparse_sums_[a].push_back(0.0);
    sparse_sums_[a][it->second] += v;
  }
  // Variance of the B² column means about the block mean m (Eq. 19 with the block as the
  // window); empty columns have mean 0 and enter as (B² − n)·m² without being stored.
  [[nodiscard]] double variance(int axis, double m) const {
    const auto a = static_cast<std::size_t>(axis);
    const std::vector<double>& sums = dense_ ? dense_sums_[a] : sparse_sums_[a];
    const double inv_b = 1.0 / b_;
    double sum = 0.0;
    double sum2 = 0.0;
    for (const double s : sums) {
      const double d = s * inv_b - m;
      sum += d;
      sum2 += d * d;
    }
    const double all = static_cast<double>(b_) * b_;
    const double empty = all - static_cast<double>(sums.size());
    sum -= empty * m;
    sum2 += empty * m * m;
    return std::max(0.0, sum2 / all - (sum / all) * (sum / all));
  }

 private:
  std::int64_t b_;
  bool dense_;
  std::array<std::vector<double>, 3> dense_sums_;
  std::array<std::unordered_map<std::uint64_t, std::size_t>, 3> index_;
  std::array<std::vector<double>, 3> sparse_sums_;  // in order of first touch (deterministic)
};

// The (p, q) of axis a's column through in-block coordinates l.
std::pair<std::int64_t, std::int64_t> column_of(int axis, const std::array<std::int64_t, 3>& l) {
  if (axis == 0) return {l[1], l[2]};
  if (axis == 1) return {l[0], l[2]};
  return {l[0], l[1]};
}

// Adds `item`'s part of block `key` to the block's total and columns.
void accumulate(const Item& item, const Key& key, const volume::BlockLattice& lattice, double& total, Columns& cols) {
  const openvdb::Coord lo(static_cast<int>(lattice.first_voxel(0, key[0])),
                          static_cast<int>(lattice.first_voxel(1, key[1])),
                          static_cast<int>(lattice.first_voxel(2, key[2])));
  const openvdb::CoordBBox bounds(lo, lo.offsetBy(lattice.factor - 1));
  if (item.leaf != nullptr) {
    for (auto v = item.leaf->cbeginValueOn(); v; ++v) {
      const openvdb::Coord c = v.getCoord();
      if (!bounds.isInside(c)) continue;
      const double value = *v;
      total += value;
      const std::array<std::int64_t, 3> l{c.x() - lo.x(), c.y() - lo.y(), c.z() - lo.z()};
      for (int a = 0; a < 3; ++a) {
        const auto [p, q] = column_of(a, l);
        cols.add(a, p, q, value);
      }
    }
    return;
  }
  // A tile: constant value over the overlap box; each column it crosses gains value × extent.
  openvdb::CoordBBox overlap = item.box;
  overlap.intersect(bounds);
  if (overlap.empty()) return;
  const double value = item.value;
  const auto dim = overlap.dim();
  total += value * static_cast<double>(dim.x()) * dim.y() * dim.z();
  for (int a = 0; a < 3; ++a) {
    const int pa = a == 0 ? 1 : 0;
    const int qa = a == 2 ? 1 : 2;
    for (int p = overlap.min()[pa]; p <= overlap.max()[pa]; ++p) {
      for (int q = overlap.min()[qa]; q <= overlap.max()[qa]; ++q) {
        cols.add(a, p - lo[pa], q - lo[qa], value * dim[a]);
      }
    }
  }
}

LocalFieldsEstimate estimate(const std::vector<Item>& items, std::uint64_t active_voxels,
                             const volume::BlockLattice& lattice) {
  const int block = lattice.factor;
  const volume::BlockLattice coarse_leaf{lattice.anchor, block * 8};
  LocalFieldsEstimate e;
  std::uint64_t coarse_leaves = 0;
  std::uint64_t tile_columns = 0;
  for (const Item& item : items) {
    const auto r = block_range(item.box, lattice);
    e.leaf_entries += range_count(r);
    coarse_leaves += range_count(block_range(item.box, coarse_leaf));
    if (item.leaf == nullptr) {
      const auto d = item.box.dim();
      tile_columns += static_cast<std::uint64_t>(d.x()) * d.y() + static_cast<std::uint64_t>(d.y()) * d.z() +
                      static_cast<std::uint64_t>(d.x()) * d.z();
    }
  }
  e.blocks = std::min(e.leaf_entries, active_voxels);
  // Entries with the sort's scratch; a result per block; ten coarse grids; the column
  // accumulators: dense per thread, or at most one stored column per active voxel and axis.
  const std::uint64_t columns = block <= kDenseBlock
                                    ? 3ULL * static_cast<std::uint64_t>(block) * block * 8 * default_thread_count()
                                    : (3 * active_voxels + tile_columns) * kColumnBytes;
  e.bytes = e.leaf_entries * sizeof(Entry) * 2 + e.blocks * sizeof(BlockResult) +
            10 * std::min(e.blocks, coarse_leaves) * kLeafBytes + columns;
  return e;
}

}  // namespace

void check_local_block(int block) {
  if (block < 1 || block > kMaxLocalBlock) {
    fail("local fields: block size must be in 1..{} voxels, got {}", kMaxLocalBlock, block);
  }
}

std::optional<WholeBoxBlock> whole_box_block(int block, const volume::Grid& grid) {
  const volume::IndexBox box = grid.active_bbox();
  if (box.empty()) return std::nullopt;  // an empty grid is refused by name where it is used
  const auto e = box.extent();
  const std::int64_t largest = *std::max_element(e.begin(), e.end());
  if (block < largest) return std::nullopt;
  return WholeBoxBlock{fmt::format("one coarse voxel of {} voxels (side {:g}) holds the whole active box of grid "
                                   "'{}' ({}x{}x{} voxels)",
                                   block, block * grid.voxel_size(), grid.name(), e[0], e[1], e[2]),
                       largest};
}

std::string thick_block_note(int block, const volume::Grid& grid) {
  const volume::IndexBox box = grid.active_bbox();
  if (box.empty()) return {};
  const auto e = box.extent();
  std::string axes;
  std::int64_t thinnest = block;
  for (int a = 0; a < 3; ++a) {
    if (e[static_cast<std::size_t>(a)] >= block) continue;
    axes += "xyz"[a];
    thinnest = std::min(thinnest, e[static_cast<std::size_t>(a)]);
  }
  if (axes.empty()) return {};
  return fmt::format(
      "blocks of {} voxels are thicker than the cloth along {} ({} voxels there): a block spreads the cloth over "
      "its whole edge, at {:.2g} of its density, and the fields reach past the cloth",
      block, axes, thinnest, static_cast<double>(thinnest) / block);
}

LocalFieldsEstimate estimate_local_fields(const volume::Grid& grid, int block) {
  check_local_block(block);
  return estimate(tree_items(*grid.impl().grid), grid.active_voxel_count(),
                  volume::block_lattice(grid.active_bbox(), block));
}

LocalFields local_fields(const volume::Grid& grid, int block, ProgressSink& progress) {
  check_local_block(block);
  if (grid.active_voxel_count() == 0) fail("local fields: grid '{}' has no active voxels", grid.name());
  const auto& vdb = *grid.impl().grid;
  const std::vector<Item> items = tree_items(vdb);
  if (items.size() > std::numeric_limits<std::uint32_t>::max()) fail("local fields: too many leaves");
  // Blocks anchored to the cloth (volume/block_lattice.h), as volume::downsample's.
  const volume::BlockLattice lattice = volume::block_lattice(grid.active_bbox(), block);
  const LocalFieldsEstimate e = estimate(items, grid.active_voxel_count(), lattice);
  const std::uint64_t budget = default_memory_budget();
  if (e.bytes > budget) {
    fail(
        "local fields: blocks of {} voxels over grid '{}' would take up to {} ({} blocks), over the memory budget "
        "of {}",
        block, grid.name(), format_bytes(e.bytes), e.blocks, format_bytes(budget));
  }
  // (block, item) pairs sorted: each block sees its leaves in tree order whatever the threads.
  std::vector<Entry> entries;
  entries.reserve(e.leaf_entries);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const auto r = block_range(items[i].box, lattice);
    for (std::int64_t x = r[0]; x <= r[3]; ++x) {
      for (std::int64_t y = r[1]; y <= r[4]; ++y) {
        for (std::int64_t z = r[2]; z <= r[5]; ++z) entries.push_back({{x, y, z}, static_cast<std::uint32_t>(i)});
      }
    }
  }
  tbb::parallel_sort(entries.begin(), entries.end());
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    if (i == 0 || entries[i].block != entries[i - 1].block) starts.push_back(i);
  }
  starts.push_back(entries.size());
  const std::size_t n_blocks = starts.size() - 1;

  std::vector<BlockResult> results(n_blocks);
  const double volume = static_cast<double>(block) * block * block;
  tbb::enumerable_thread_specific<Columns> columns(block);
  ProgressTask task(progress, "local fields", n_blocks);
  parallel_units(n_blocks, [&](std::size_t u) {
    Columns& cols = columns.local();
    cols.reset();
    BlockResult r;
    r.key = entries[starts[u]].block;
    double total = 0.0;
    for (std::size_t i = starts[u]; i < starts[u + 1]; ++i)
      accumulate(items[entries[i].item], r.key, lattice, total, cols);
    r.mean = total / volume;
    for (int a = 0; a < 3; ++a) r.variance[static_cast<std::size_t>(a)] = cols.variance(a, r.mean);
    results[u] = r;
    task.step();
  });

  LocalFields out;
  out.block = block;
  const double coarse = grid.voxel_size() * block;
  const auto origin = lattice.coarse_origin(grid.origin(), grid.voxel_size());
  auto make = [&](const std::string& name) {
    volume::Grid g(coarse, name);
    g.set_origin(origin);
    for (const auto& [k, v] : grid.metadata()) {
      if (k.rfind("weft:", 0) == 0) g.set_metadata(k, v);
    }
    g.set_metadata("weft:local_block_voxels", std::to_string(block));
    return g;
  };
  out.mean = make("mean_concentration");
  for (int a = 0; a < 3; ++a) {
    const char axis = "xyz"[a];
    out.variance[static_cast<std::size_t>(a)] = make(fmt::format("var_concentration_{}", axis));
    out.alpha[static_cast<std::size_t>(a)] = make(fmt::format("alpha_{}", axis));
    out.beta[static_cast<std::size_t>(a)] = make(fmt::format("beta_{}", axis));
  }
  // One accessor per grid for the whole loop: Grid::set_value makes (and registers with the tree)
  // an accessor per call and walks from the root, 40 % of the local fields' CPU in `weft validate
  // --sweep` (docs/benchmarks.md "Every core busy: the sweep's serial pieces"). Same trees.
  using Accessor = openvdb::FloatGrid::Accessor;
  Accessor mean_acc = out.mean.impl().grid->getAccessor();
  std::array<std::array<Accessor, 3>, 3> axis_acc{{
      {out.variance[0].impl().grid->getAccessor(), out.variance[1].impl().grid->getAccessor(),
       out.variance[2].impl().grid->getAccessor()},
      {out.alpha[0].impl().grid->getAccessor(), out.alpha[1].impl().grid->getAccessor(),
       out.alpha[2].impl().grid->getAccessor()},
      {out.beta[0].impl().grid->getAccessor(), out.beta[1].impl().grid->getAccessor(),
       out.beta[2].impl().grid->getAccessor()},
  }};
  // The variances are stored as 16-bit floats when they all fit half's range (docs/render.md §5b
  // "Storage"; always for concentrations in [0, 1], whose V ≤ ¼): a block's variance is itself
  // an estimate from its B² column means, whose relative sampling error (≈ √(2/B²) for
  // independent columns, 18 % at B = 8) dwarfs half's 2⁻¹¹, so the low bits of a float would
  // store noise; 2 bytes instead of 4 on three of the four channels the medium reads. Grids of
  // larger values (an extinction grid in large length units, e.g. 1/m) keep float variances.
  bool half = true;
  for (const auto& r : results) {
    for (const double v : r.variance) half = half && !(v > volume::kHalfMax);
  }
  for (const auto& r : results) {
    if (!(r.mean > 0.0)) continue;
    const openvdb::Coord ijk(static_cast<int>(r.key[0]), static_cast<int>(r.key[1]), static_cast<int>(r.key[2]));
    mean_acc.setValue(ijk, static_cast<float>(r.mean));
    for (std::size_t a = 0; a < 3; ++a) {
      // The variance as stored, so α and β are those of the stored fields.
      const auto var = static_cast<float>(r.variance[a]);
      const float stored = half ? volume::half_precision(var) : var;
      axis_acc[0][a].setValue(ijk, stored);
      const transmittance::ShapeRate s = transmittance::gamma_shape_rate(r.mean, stored);
      axis_acc[1][a].setValue(ijk, static_cast<float>(s.alpha));
      axis_acc[2][a].setValue(ijk, static_cast<float>(s.beta));
    }
    ++out.blocks;
  }
  if (half) {
    for (volume::Grid& v : out.variance) v.store_as_half();  // rounded above: only flags the grids
  }
  return out;
}

std::string_view field_channels_name(FieldChannels channels) {
  return channels == FieldChannels::render ? "render" : "all";
}

std::optional<FieldChannels> parse_field_channels(std::string_view name) {
  for (const FieldChannels c : {FieldChannels::render, FieldChannels::all})
    if (name == field_channels_name(c)) return c;
  return std::nullopt;
}

void save_local_fields(const LocalFields& f, const std::filesystem::path& path, FieldChannels channels) {
  std::vector<volume::Grid> grids{f.mean};
  for (std::size_t a = 0; a < 3; ++a) grids.push_back(f.variance[a]);
  if (channels == FieldChannels::all) {
    for (std::size_t a = 0; a < 3; ++a) grids.push_back(f.alpha[a]);
    for (std::size_t a = 0; a < 3; ++a) grids.push_back(f.beta[a]);
  }
  volume::save_grids(grids, path);
}

}  // namespace weft::fit
