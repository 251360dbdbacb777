// Downsampling with the extinction corrected for self-shadowing (shadowed_downsample.h;
// docs/render.md §6d).
#include "weft/volume/shadowed_downsample.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/volume/block_lattice.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

/// −ln T̄ for T̄ = (Σ_j e^{−τ_j} + absent)/columns: the present columns' depths τ_j ≥ 0 and
/// `absent` columns of depth 0 (outside the grid's active box).
double minus_log_mean_transmittance(const std::vector<double>& depths, double absent, double columns) {
  double sum_expm1 = 0.0;
  for (const double tau : depths) sum_expm1 += std::expm1(-tau);
  const double m = sum_expm1 / columns;  // T̄ − 1 ∈ [−1, 0]
  if (m > -0.5) return -std::log1p(m);   // T̄ ≥ 1/2: log1p keeps thin blocks exact
  // T̄ < 1/2: log-sum-exp with the largest term (the thinnest column) factored out, so an
  // opaque block gives a large finite −ln T̄ instead of −ln 0.
  double tau_min = absent > 0.0 ? 0.0 : depths.front();
  for (const double tau : depths) tau_min = std::min(tau_min, tau);
  double s = absent;  // absent columns: e^{−0 + τ_min} with τ_min = 0 when there are any
  for (const double tau : depths) s += std::exp(tau_min - tau);
  return tau_min - std::log(s) + std::log(columns);
}

/// One coarse voxel: the three per-axis values and the isotropic one.
struct BlockValues {
  openvdb::Coord coarse;
  std::array<double, 3> axis{};
  double isotropic = 0.0;
};

}  // namespace

ShadowedGrids shadowed_downsample(const Grid& fine, int factor, double scale) {
  if (factor < 1 || factor > 4096) fail("shadowed downsample: factor must be in 1..4096, got {}", factor);
  if (!(std::isfinite(scale) && scale > 0.0))
    fail("shadowed downsample: the extinction per unit value must be finite and > 0, got {}", scale);
  if (fine.active_voxel_count() == 0) fail("shadowed downsample: grid '{}' has no active voxels", fine.name());
  ensure_openvdb_initialized();
  const auto& src = *fine.impl().grid;
  const IndexBox box = fine.active_bbox();
  const int f = factor;
  const double kappa = scale * fine.voxel_size();  // optical depth of one fine voxel per unit value
  const double columns = static_cast<double>(f) * static_cast<double>(f);
  const double cells = columns * static_cast<double>(f);
  // Blocks anchored to the cloth (volume/block_lattice.h): block 0 starts at the box's corner.
  const BlockLattice lattice = block_lattice(box, f);
  std::array<int, 3> blocks{};
  for (std::size_t a = 0; a < 3; ++a)
    blocks[a] = static_cast<int>(lattice.block_of(static_cast<int>(a), box.max[a])) + 1;

  // One work unit per slab of blocks (fixed I): each block is computed alone, in index order,
  // so the values do not depend on the thread count.
  std::vector<std::vector<BlockValues>> slabs(static_cast<std::size_t>(blocks[0]));
  parallel_units(slabs.size(), [&](std::size_t unit) {
    auto acc = src.getConstAccessor();
    std::array<std::vector<double>, 3> depth;  // per axis a: the column sums over the clipped block
    for (int bj = 0; bj < blocks[1]; ++bj) {
      for (int bk = 0; bk < blocks[2]; ++bk) {
        const std::array<int, 3> b{static_cast<int>(unit), bj, bk};
        std::array<int, 3> lo{};
        std::array<int, 3> n{};  // the block clipped to the active box: voxels outside are 0
        for (std::size_t a = 0; a < 3; ++a) {
          lo[a] = static_cast<int>(lattice.first_voxel(static_cast<int>(a), b[a]));
          n[a] = std::min(lo[a] + f - 1, box.max[a]) - lo[a] + 1;
        }
        // depth[a] is indexed by the two other coordinates (u, v) in increasing axis order.
        depth[0].assign(static_cast<std::size_t>(n[1]) * static_cast<std::size_t>(n[2]), 0.0);
        depth[1].assign(static_cast<std::size_t>(n[0]) * static_cast<std::size_t>(n[2]), 0.0);
        depth[2].assign(static_cast<std::size_t>(n[0]) * static_cast<std::size_t>(n[1]), 0.0);
        bool active = false;
        double sum = 0.0;
        for (int i = 0; i < n[0]; ++i) {
          for (int j = 0; j < n[1]; ++j) {
            for (int k = 0; k < n[2]; ++k) {
              float v = 0.0F;
              if (!acc.probeValue(openvdb::Coord(lo[0] + i, lo[1] + j, lo[2] + k), v)) continue;
              active = true;
              const double x = static_cast<double>(v);
              sum += x;
              const auto ui = static_cast<std::size_t>(i);
              const auto uj = static_cast<std::size_t>(j);
              const auto uk = static_cast<std::size_t>(k);
              depth[0][uj * static_cast<std::size_t>(n[2]) + uk] += x;
              depth[1][ui * static_cast<std::size_t>(n[2]) + uk] += x;
              depth[2][ui * static_cast<std::size_t>(n[1]) + uj] += x;
            }
          }
        }
        if (!active) continue;
        const double mean = sum / cells;  // volume::downsample's value
        BlockValues out;
        out.coarse = openvdb::Coord(b[0], b[1], b[2]);
        for (std::size_t a = 0; a < 3; ++a) {
          std::vector<double>& d = depth[a];
          const double absent = columns - static_cast<double>(d.size());
          const auto [lo_it, hi_it] = std::minmax_element(d.begin(), d.end());
          // Every column equally deep (absent ones are 0 deep): T̄ = e^{−τ} exactly, so the
          // value is the block mean with nothing to correct.
          if (*lo_it == *hi_it && (absent == 0.0 || *hi_it == 0.0)) {
            out.axis[a] = mean;
            continue;
          }
          for (double& x : d) x *= kappa;
          const double minus_log_t = minus_log_mean_transmittance(d, absent, columns);
          // Jensen: −ln T̄ ≤ mean τ, i.e. the value ≤ the mean; the cap only removes rounding.
          out.axis[a] = std::clamp(minus_log_t / (kappa * f), 0.0, mean);
        }
        out.isotropic = out.axis[0] == out.axis[1] && out.axis[1] == out.axis[2]
                            ? out.axis[0]
                            : (out.axis[0] + out.axis[1] + out.axis[2]) / 3.0;
        slabs[unit].push_back(out);
      }
    }
  });

  const auto make = [&](const std::string& name) {
    Grid g(fine.voxel_size() * f, name);
    g.set_origin(lattice.coarse_origin(fine.origin(), fine.voxel_size()));
    for (const auto& [k, v] : fine.metadata()) {
      if (k.rfind("weft:", 0) == 0) g.set_metadata(k, v);
    }
    g.set_metadata("weft:downsample_factor", std::to_string(f));
    g.set_metadata("weft:downsample_rule", "shadowed");
    g.set_metadata("weft:shadow_scale", fmt::format("{:.17g}", scale));
    return g;
  };
  ShadowedGrids out{{make(fine.name() + "_x"), make(fine.name() + "_y"), make(fine.name() + "_z")}, make(fine.name())};
  std::array<openvdb::FloatGrid::Accessor, 3> axis_acc{out.per_axis[0].impl().grid->getAccessor(),
                                                       out.per_axis[1].impl().grid->getAccessor(),
                                                       out.per_axis[2].impl().grid->getAccessor()};
  auto iso_acc = out.isotropic.impl().grid->getAccessor();
  for (const auto& slab : slabs) {
    for (const BlockValues& v : slab) {
      for (std::size_t a = 0; a < 3; ++a) axis_acc[a].setValueOn(v.coarse, static_cast<float>(v.axis[a]));
      iso_acc.setValueOn(v.coarse, static_cast<float>(v.isotropic));
    }
  }
  return out;
}

}  // namespace weft::volume
