#include "weft/volume/dense.h"

#include <cmath>
#include <limits>

#include <openvdb/tools/Dense.h>

#include "weft/core/error.h"
#include "weft/core/memory.h"
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

void copy_to_dense(const Grid& grid, const IndexBox& box, float* out, DenseLayout layout) {
  if (box.empty()) return;
  require_index_range(box, "dense copy: index box");  // copyToDense's node steps overflow past it
  if (layout == DenseLayout::x_major) {
    // OpenVDB's LayoutZYX: z varies fastest, i.e. C order of an (nx, ny, nz) array [i][j][k].
    openvdb::tools::Dense<float, openvdb::tools::LayoutZYX> dense(to_bbox(box), out);
    openvdb::tools::copyToDense(*grid.impl().grid, dense);
  } else {
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(to_bbox(box), out);
    openvdb::tools::copyToDense(*grid.impl().grid, dense);
  }
}

std::vector<float> to_dense(const Grid& grid, const IndexBox& box, std::uint64_t max_bytes) {
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
  copy_to_dense(grid, box, values.data());
  return values;
}

void from_dense(Grid& grid, const std::array<int, 3>& min, const std::array<std::int64_t, 3>& extent,
                const float* values) {
  // copyFromDense's node steps overflow past kMaxIndex (grid.h): refused before any voxel is written.
  for (int a = 0; a < 3; ++a) {
    if (extent[a] < 0) fail("dense copy: extent {} along axis {} is negative", extent[a], a);
    if (min[a] < -kMaxIndex || std::int64_t{min[a]} + extent[a] - 1 > kMaxIndex)
      fail("dense copy: index_origin ({}, {}, {}) with shape ({}, {}, {}) leaves, along axis {}, {}", min[0], min[1],
           min[2], extent[0], extent[1], extent[2], a, index_range_text());
  }
  const std::int64_t n = extent[0] * extent[1] * extent[2];
  for (std::int64_t q = 0; q < n; ++q) {
    const float v = values[q];
    if (!std::isfinite(v) || v < 0.0f) {
      const std::int64_t k = q % extent[2];
      const std::int64_t j = (q / extent[2]) % extent[1];
      const std::int64_t i = q / (extent[1] * extent[2]);
      fail("dense copy: value {} at index ({}, {}, {}); grid values must be finite and >= 0", v, i, j, k);
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
