#include "weft/volume/columns.h"

#include <algorithm>

#include "weft/core/error.h"
#include "weft/core/floor_div.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/pass_budget.h"

namespace weft::volume {
namespace {
constexpr int kPatch = 8;  // matches the leaf size, so a leaf falls in exactly one patch
}

struct ColumnReader::Impl {
  openvdb::FloatGrid::ConstPtr grid;
  int axis = 2;
  int ua = 0;  // first transverse axis
  int va = 1;  // second transverse axis
  IndexBox box;
  std::int64_t base_u = 0;
  std::int64_t base_v = 0;
  std::int64_t tiles_u = 0;
  std::int64_t tiles_v = 0;
  std::vector<std::vector<const openvdb::FloatTree::LeafNodeType*>> leaves;  // per patch
  struct ActiveTile {
    openvdb::CoordBBox bbox;
    float value;
  };
  std::vector<ActiveTile> tiles;             // active tiles above leaf level (rare)
  std::vector<std::uint8_t> patch_has_tile;  // per patch: overlapped by one of `tiles`

  /// Where patch `tile` lies: its columns clipped to the active box, the box's whole depth.
  [[nodiscard]] PatchFrame frame(std::size_t tile) const {
    const auto tu = static_cast<std::int64_t>(tile) / tiles_v;
    const auto tv = static_cast<std::int64_t>(tile) % tiles_v;
    PatchFrame f;
    f.u0 = std::max<std::int64_t>(base_u + tu * kPatch, box.min[ua]);
    f.v0 = std::max<std::int64_t>(base_v + tv * kPatch, box.min[va]);
    f.nu = static_cast<int>(std::min<std::int64_t>(base_u + (tu + 1) * kPatch - 1, box.max[ua]) - f.u0 + 1);
    f.nv = static_cast<int>(std::min<std::int64_t>(base_v + (tv + 1) * kPatch - 1, box.max[va]) - f.v0 + 1);
    f.depth0 = box.min[axis];
    f.depth = static_cast<int>(box.max[axis] - box.min[axis] + 1);
    return f;
  }
};

namespace {}  // namespace

ColumnReader::ColumnReader(const Grid& grid, int axis) : impl_(std::make_unique<Impl>()) {
  if (axis < 0 || axis > 2) fail("column reader: axis must be 0, 1 or 2, got {}", axis);
  auto& m = *impl_;
  m.grid = grid.impl().grid;
  m.axis = axis;
  m.ua = (axis + 1) % 3;
  m.va = (axis + 2) % 3;
  m.box = grid.active_bbox();
  if (m.box.empty()) return;
  m.base_u = floor_div(m.box.min[m.ua], kPatch) * kPatch;
  m.base_v = floor_div(m.box.min[m.va], kPatch) * kPatch;
  m.tiles_u = floor_div(m.box.max[m.ua] - m.base_u, kPatch) + 1;
  m.tiles_v = floor_div(m.box.max[m.va] - m.base_v, kPatch) + 1;
  check_pass_cost(fmt::format("the voxel columns along {}", "xyz"[axis]), grid, column_pass_cost(m.box, axis));
  m.leaves.resize(static_cast<std::size_t>(m.tiles_u * m.tiles_v));
  const auto& tree = m.grid->tree();
  for (auto it = tree.cbeginLeaf(); it; ++it) {
    if (it->isEmpty()) continue;
    const openvdb::Coord o = it->origin();
    const std::int64_t tu = floor_div(o[m.ua] - m.base_u, kPatch);
    const std::int64_t tv = floor_div(o[m.va] - m.base_v, kPatch);
    m.leaves[static_cast<std::size_t>(tu * m.tiles_v + tv)].push_back(&*it);
  }
  // Leaves of a patch in depth order (read_sparse emits slices in increasing depth).
  for (auto& list : m.leaves) {
    std::sort(list.begin(), list.end(),
              [&](const auto* a, const auto* b) { return a->origin()[m.axis] < b->origin()[m.axis]; });
  }
  // Active tiles only: stopping above the leaf level skips the voxels themselves.
  auto it = tree.cbeginValueOn();
  it.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; it; ++it) {
    if (it.isVoxelValue()) continue;
    openvdb::CoordBBox b;
    it.getBoundingBox(b);
    m.tiles.push_back({b, *it});
  }
  m.patch_has_tile.assign(m.leaves.size(), 0);
  for (const auto& t : m.tiles) {
    const std::int64_t tu0 = std::max<std::int64_t>(floor_div(t.bbox.min()[m.ua] - m.base_u, kPatch), 0);
    const std::int64_t tu1 = std::min<std::int64_t>(floor_div(t.bbox.max()[m.ua] - m.base_u, kPatch), m.tiles_u - 1);
    const std::int64_t tv0 = std::max<std::int64_t>(floor_div(t.bbox.min()[m.va] - m.base_v, kPatch), 0);
    const std::int64_t tv1 = std::min<std::int64_t>(floor_div(t.bbox.max()[m.va] - m.base_v, kPatch), m.tiles_v - 1);
    for (std::int64_t tu = tu0; tu <= tu1; ++tu) {
      for (std::int64_t tv = tv0; tv <= tv1; ++tv) m.patch_has_tile[static_cast<std::size_t>(tu * m.tiles_v + tv)] = 1;
    }
  }
}

ColumnReader::~ColumnReader() = default;

PassCost column_pass_cost(const IndexBox& box, int axis) {
  if (box.empty()) return {};
  const auto e = box.extent();
  const int ua = (axis + 1) % 3;
  const int va = (axis + 2) % 3;
  // Patches: a box edge of n voxels starts anywhere in a patch, so it meets at most n/8 + 2.
  const double patches = (static_cast<double>(e[ua]) / kPatch + 2.0) * (static_cast<double>(e[va]) / kPatch + 2.0);
  PassCost c;
  c.steps = static_cast<double>(e[0]) * static_cast<double>(e[1]) * static_cast<double>(e[2]);
  c.bytes = patches * static_cast<double>(sizeof(std::vector<const void*>) + sizeof(std::uint8_t));
  return c;
}

int ColumnReader::axis() const { return impl_->axis; }
IndexBox ColumnReader::box() const { return impl_->box; }
std::size_t ColumnReader::tile_count() const { return static_cast<std::size_t>(impl_->tiles_u * impl_->tiles_v); }
std::uint64_t ColumnReader::column_count() const {
  if (impl_->box.empty()) return 0;
  const auto e = impl_->box.extent();
  return static_cast<std::uint64_t>(e[impl_->ua] * e[impl_->va]);
}

void ColumnReader::read(std::size_t tile, ColumnTile& out) const {
  const auto& m = *impl_;
  if (tile >= tile_count()) fail("column reader: patch {} out of range ({} patches)", tile, tile_count());
  const auto tu = static_cast<std::int64_t>(tile) / m.tiles_v;
  const auto tv = static_cast<std::int64_t>(tile) % m.tiles_v;
  const std::int64_t u0 = std::max<std::int64_t>(m.base_u + tu * kPatch, m.box.min[m.ua]);
  const std::int64_t u1 = std::min<std::int64_t>(m.base_u + (tu + 1) * kPatch - 1, m.box.max[m.ua]);
  const std::int64_t v0 = std::max<std::int64_t>(m.base_v + tv * kPatch, m.box.min[m.va]);
  const std::int64_t v1 = std::min<std::int64_t>(m.base_v + (tv + 1) * kPatch - 1, m.box.max[m.va]);
  out.axis = m.axis;
  out.u0 = u0;
  out.v0 = v0;
  out.nu = static_cast<int>(u1 - u0 + 1);
  out.nv = static_cast<int>(v1 - v0 + 1);
  out.depth0 = m.box.min[m.axis];
  out.depth = static_cast<int>(m.box.max[m.axis] - m.box.min[m.axis] + 1);
  out.values.assign(
      static_cast<std::size_t>(out.nu) * static_cast<std::size_t>(out.nv) * static_cast<std::size_t>(out.depth), 0.0f);
  const auto put = [&](std::int64_t cu, std::int64_t cv, std::int64_t ca, float value) {
    if (cu < u0 || cu > u1 || cv < v0 || cv > v1) return;
    const std::size_t idx =
        (static_cast<std::size_t>(cu - u0) * static_cast<std::size_t>(out.nv) + static_cast<std::size_t>(cv - v0)) *
            static_cast<std::size_t>(out.depth) +
        static_cast<std::size_t>(ca - out.depth0);
    out.values[idx] = value;
  };
  // Leaves lie inside the active box and inside one patch: no bounds checks per voxel.
  using Leaf = openvdb::FloatTree::LeafNodeType;
  const auto su = static_cast<std::size_t>(out.nv) * static_cast<std::size_t>(out.depth);
  const auto sv = static_cast<std::size_t>(out.depth);
  for (const auto* leaf : m.leaves[tile]) {
    const openvdb::Coord o = leaf->origin();
    const float* data = leaf->buffer().data();
    for (auto on = leaf->getValueMask().beginOn(); on; ++on) {
      const openvdb::Index n = on.pos();
      const openvdb::Coord c = o + Leaf::offsetToLocalCoord(n);
      out.values[static_cast<std::size_t>(c[m.ua] - u0) * su + static_cast<std::size_t>(c[m.va] - v0) * sv +
                 static_cast<std::size_t>(c[m.axis] - out.depth0)] = data[n];
    }
  }
  for (const auto& t : m.tiles) {
    const auto& b = t.bbox;
    const std::int64_t a0 = std::max<std::int64_t>(b.min()[m.ua], u0);
    const std::int64_t a1 = std::min<std::int64_t>(b.max()[m.ua], u1);
    const std::int64_t c0 = std::max<std::int64_t>(b.min()[m.va], v0);
    const std::int64_t c1 = std::min<std::int64_t>(b.max()[m.va], v1);
    const std::int64_t d0 = std::max<std::int64_t>(b.min()[m.axis], out.depth0);
    const std::int64_t d1 = std::min<std::int64_t>(b.max()[m.axis], m.box.max[m.axis]);
    for (std::int64_t cu = a0; cu <= a1; ++cu) {
      for (std::int64_t cv = c0; cv <= c1; ++cv) {
        for (std::int64_t ca = d0; ca <= d1; ++ca) put(cu, cv, ca, t.value);
      }
    }
  }
}

bool ColumnReader::read_sparse(std::size_t tile, SparseColumnTile& out) const {
  const auto& m = *impl_;
  if (tile >= tile_count()) fail("column reader: patch {} out of range ({} patches)", tile, tile_count());
  if (m.patch_has_tile[tile] != 0) return false;
  out.axis = m.axis;
  static_cast<PatchFrame&>(out) = m.frame(tile);
  out.slices.clear();
  std::uint32_t used = 0;  // entries written; the vectors only grow (no clearing, no per-entry checks)
  // A leaf lies in one patch and spans 8 depth slices (leaf-local coordinate `sl` along the
  // axis). Its value mask is 8 words, word x holding bit y·8 + z: the active voxels of a slice
  // are read from the words with shifts and masks, slice by slice, so they come out grouped by
  // slice without a sort. Leaves are in depth order and do not overlap: so are the slices.
  const auto nv = static_cast<std::int64_t>(out.nv);
  for (const auto* leaf : m.leaves[tile]) {
    const openvdb::Coord o = leaf->origin();
    const float* data = leaf->buffer().data();
    const auto& mask = leaf->getValueMask();
    const std::int64_t cu0 = o[m.ua] - out.u0;
    const std::int64_t cv0 = o[m.va] - out.v0;
    if (out.column.size() < used + 512U) {
      out.column.resize(used + 512U);
      out.value.resize(used + 512U);
    }
    std::uint16_t* column = out.column.data();
    float* value = out.value.data();
    // Appends voxel (x, y, z) of the leaf, whose transverse coordinates are (lu, lv).
    const auto put = [&](std::uint32_t x, std::uint32_t y, std::uint32_t z, std::int64_t lu, std::int64_t lv) {
      column[used] = static_cast<std::uint16_t>((cu0 + lu) * nv + cv0 + lv);
      value[used++] = data[(x << 6) | (y << 3) | z];
    };
    for (std::uint32_t sl = 0; sl < 8; ++sl) {
      const std::uint32_t begin = used;
      if (m.axis == 0) {  // slice x = sl: word sl; (u, v) = (y, z)
        for (std::uint64_t w = mask.getWord<std::uint64_t>(sl); w != 0; w &= w - 1) {
          const auto b = static_cast<std::uint32_t>(__builtin_ctzll(w));
          put(sl, b >> 3, b & 7U, b >> 3, b & 7U);
        }
      } else if (m.axis == 1) {  // slice y = sl: byte sl of every word; (u, v) = (z, x)
        for (std::uint32_t x = 0; x < 8; ++x) {
          for (std::uint64_t w = (mask.getWord<std::uint64_t>(x) >> (8 * sl)) & 0xffU; w != 0; w &= w - 1) {
            const auto z = static_cast<std::uint32_t>(__builtin_ctzll(w));
            put(x, sl, z, z, x);
          }
        }
      } else {  // slice z = sl: bit sl of every byte; (u, v) = (x, y)
        for (std::uint32_t x = 0; x < 8; ++x) {
          for (std::uint64_t w = (mask.getWord<std::uint64_t>(x) >> sl) & 0x0101010101010101ULL; w != 0; w &= w - 1) {
            const auto y = static_cast<std::uint32_t>(__builtin_ctzll(w)) >> 3;
            put(x, y, sl, x, y);
          }
        }
      }
      if (used > begin)
        out.slices.push_back({static_cast<int>(o[m.axis] + static_cast<int>(sl) - out.depth0), begin, used});
    }
  }
  return true;
}

bool ColumnReader::read_columns(std::size_t tile, SparseColumns& out) const {
  const auto& m = *impl_;
  if (tile >= tile_count()) fail("column reader: patch {} out of range ({} patches)", tile, tile_count());
  if (m.patch_has_tile[tile] != 0) return false;
  static_cast<PatchFrame&>(out) = m.frame(tile);
  out.count.fill(0U);
  const auto depth = static_cast<std::size_t>(out.depth);
  const std::size_t need = std::size_t{kPatch} * std::size_t{kPatch} * depth;
  if (out.k.size() < need) {
    out.k.resize(need);
    out.value.resize(need);
  }
  // Active voxels of value 0 are left out (written, then overwritten: no branch per voxel):
  // they add nothing to a sum, and a column of only such voxels is empty to every pass.
  // A leaf's active voxels in offset order (x·64 + y·8 + z) come, for every column across any
  // axis, in increasing depth (the column fixes the two other coordinates); leaves are in depth
  // order and do not overlap along a column: so each column's voxels come out in depth order,
  // without slices or a sort. Along z a column is one byte of a mask word (its 8 depths).
  const auto nv = static_cast<std::size_t>(out.nv);
  int* ks = out.k.data();
  float* vs = out.value.data();
  const auto& leaves = m.leaves[tile];
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const auto* leaf = leaves[i];
    const openvdb::Coord o = leaf->origin();
    const float* data = leaf->buffer().data();
    const auto& mask = leaf->getValueMask();
    // The next leaf's values (2 KB, a separate allocation: no hardware prefetcher follows) are
    // requested while this one's are read: the value loads were where this loop waited.
    if (i + 1 < leaves.size()) {
      const char* next = reinterpret_cast<const char*>(leaves[i + 1]->buffer().data());
      for (std::size_t line = 0; line < sizeof(float) * openvdb::FloatTree::LeafNodeType::SIZE; line += 64) {
        __builtin_prefetch(next + line);
      }
    }
    const auto cu0 = static_cast<std::size_t>(o[m.ua] - out.u0);
    const auto cv0 = static_cast<std::size_t>(o[m.va] - out.v0);
    const auto k0 = static_cast<int>(o[m.axis] - out.depth0);
    for (std::uint32_t x = 0; x < 8; ++x) {
      const auto word = mask.getWord<std::uint64_t>(x);
      if (m.axis == 2) {  // (u, v) = (x, y): byte y of word x is the column's 8 depths
        for (std::uint32_t y = 0; y < 8; ++y) {
          std::uint64_t z_bits = (word >> (8 * y)) & 0xffU;
          if (z_bits == 0) continue;
          const std::size_t c = (cu0 + x) * nv + cv0 + y;
          std::size_t at = c * depth + out.count[c];
          for (; z_bits != 0; z_bits &= z_bits - 1) {
            const auto z = static_cast<std::uint32_t>(__builtin_ctzll(z_bits));
            const float v = data[(x << 6U) | (y << 3U) | z];
            ks[at] = k0 + static_cast<int>(z);
            vs[at] = v;
            at += v != 0.0f ? 1U : 0U;
          }
          out.count[c] = static_cast<std::uint32_t>(at - c * depth);
        }
        continue;
      }
      for (std::uint64_t w = word; w != 0; w &= w - 1) {
        const auto b = static_cast<std::uint32_t>(__builtin_ctzll(w));  // y·8 + z
        const std::uint32_t y = b >> 3U;
        const std::uint32_t z = b & 7U;
        // Along x: (u, v) = (y, z), depth x; along y: (u, v) = (z, x), depth y.
        const std::size_t c = m.axis == 0 ? (cu0 + y) * nv + cv0 + z : (cu0 + z) * nv + cv0 + x;
        const std::size_t at = c * depth + out.count[c];
        const float v = data[(x << 6U) | b];
        ks[at] = k0 + static_cast<int>(m.axis == 0 ? x : y);
        vs[at] = v;
        out.count[c] += v != 0.0f ? 1U : 0U;
      }
    }
  }
  return true;
}

}  // namespace weft::volume
