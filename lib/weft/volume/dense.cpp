#include "weft/volume/dense.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <openvdb/tools/Dense.h>

#include "weft/core/error.h"
#include "weft/core/floor_div.h"
#include "weft/core/memory.h"
#include "weft/core/parallel.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {

std::uint64_t dense_bytes(const IndexBox& box) {
  if (box.empty()) return 0;
  const auto e = box.extent();
  std::uint64_t n = sizeof(float);
  for (const std::int64_t d : e) {
    const auto u = static_cast<std::uint64_t>(d);
    if (n > std::numeric_limits<std::uint64_t>::max() / u) return std::numeric_limits<std::uint64_t>::max();
    n *= u;
  }
  return n;
}

namespace {
openvdb::CoordBBox to_bbox(const IndexBox& box) {
  return {openvdb::Coord(box.min[0], box.min[1], box.min[2]), openvdb::Coord(box.max[0], box.max[1], box.max[2])};
}
}  // namespace

void copy_to_dense(const Grid& grid, const IndexBox& box, float* out, DenseLayout layout, ProgressSink& progress) {
  if (box.empty()) return;
  require_index_range(box, "dense copy: index box");  // copyToDense's node steps overflow past it
  // Not tools::copyToDense: its parallel form splits the box at (min + max) >> 1 in 32-bit Coord
  // arithmetic (CoordBBox's TBB splitting constructor), which overflows once |min + max| passes
  // 2^31 - 1, i.e. for any box beyond index 2^30 (docs/robustness.md "Index range"). The box is cut
  // here instead, in 64-bit arithmetic, into slabs one leaf (8 voxels) thick along the layout's
  // slowest axis, each slab a contiguous stretch of `out` and one progress unit.
  const int axis = layout == DenseLayout::x_major ? 0 : 2;
  constexpr std::int64_t kLeaf = openvdb::FloatTree::LeafNodeType::DIM;
  const std::int64_t first = floor_div(box.min[axis], kLeaf);
  const auto slabs = static_cast<std::uint64_t>(floor_div(box.max[axis], kLeaf) - first + 1);
  ProgressTask task(progress, "dense copy", slabs);
  const auto copy = [&](auto& dense) {
    const auto& root = grid.impl().grid->tree().root();
    parallel_units(slabs, [&](std::size_t unit) {
      openvdb::CoordBBox slab = to_bbox(box);
      const std::int64_t lo = (first + static_cast<std::int64_t>(unit)) * kLeaf;
      slab.min()[axis] = static_cast<int>(std::max<std::int64_t>(box.min[axis], lo));
      slab.max()[axis] = static_cast<int>(std::min<std::int64_t>(box.max[axis], lo + kLeaf - 1));
      root.copyToDense(slab, dense);
      task.step();
    });
  };
  if (layout == DenseLayout::x_major) {
    // OpenVDB's LayoutZYX: z varies fastest, i.e. C order of an (nx, ny, nz) array [i][j][k].
    openvdb::tools::Dense<float, openvdb::tools::LayoutZYX> dense(to_bbox(box), out);
    copy(dense);
  } else {
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(to_bbox(box), out);
    copy(dense);
  }
}

std::vector<float> to_dense(const Grid& grid, const IndexBox& box, std::uint64_t max_bytes, ProgressSink& progress) {
  if (box.empty()) fail("dense copy: the box is empty");
  require_index_range(box, "dense copy: index box");
  const std::uint64_t bytes = dense_bytes(box);
  if (bytes > max_bytes) {
    const auto e = box.extent();
    fail("dense copy: box ({}, {}, {})..({}, {}, {}) is {}x{}x{} voxels = {:.4g} MiB, over the limit of {}", box.min[0],
         box.min[1], box.min[2], box.max[0], box.max[1], box.max[2], e[0], e[1], e[2],
         static_cast<double>(bytes) / (1024.0 * 1024.0), format_bytes(max_bytes));
  }
  std::vector<float> values(bytes / sizeof(float));
  copy_to_dense(grid, box, values.data(), DenseLayout::x_major, progress);
  return values;
}

void from_dense(Grid& grid, const std::array<int, 3>& min, const std::array<std::int64_t, 3>& extent,
                const float* values, std::string_view what) {
  // copyFromDense's node steps overflow past kMaxIndex (grid.h): refused before any voxel is written.
  for (int a = 0; a < 3; ++a) {
    if (extent[a] < 0) fail("{}: extent {} along axis {} is negative", what, extent[a], a);
    if (min[a] < -kMaxIndex || std::int64_t{min[a]} + extent[a] - 1 > kMaxIndex)
      fail("{}: index_origin ({}, {}, {}) with shape ({}, {}, {}) leaves, along axis {}, {}", what, min[0], min[1],
           min[2], extent[0], extent[1], extent[2], a, index_range_text());
  }
  const std::int64_t n = extent[0] * extent[1] * extent[2];
  for (std::int64_t q = 0; q < n; ++q) {
    const float v = values[q];
    if (!std::isfinite(v) || v < 0.0f) {
      const std::int64_t k = q % extent[2];
      const std::int64_t j = (q / extent[2]) % extent[1];
      const std::int64_t i = q / (extent[1] * extent[2]);
      fail("{}: value {} at index ({}, {}, {}); grid values must be finite and >= 0", what, v, i, j, k);
    }
  }
  if (n == 0) return;
  const IndexBox box{{min[0], min[1], min[2]},
                     {static_cast<int>(min[0] + extent[0] - 1), static_cast<int>(min[1] + extent[1] - 1),
                      static_cast<int>(min[2] + extent[2] - 1)}};
  // Dense only reads here (copyFromDense), whatever its pointer type says.
  openvdb::tools::Dense<float, openvdb::tools::LayoutZYX> dense(to_bbox(box), const_cast<float*>(values));
  // Tolerance 0: exactly the zeros become background (inactive).
  openvdb::tools::copyFromDense(dense, *grid.impl().grid, 0.0f);
}

}  // namespace weft::volume
