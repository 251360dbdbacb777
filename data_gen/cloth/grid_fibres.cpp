#include "data_gen/cloth/grid_fibres.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/pattern.h"
#include "weft/core/error.h"
#include "weft/core/parse_number.h"

namespace weft::cloth {

fibres::FibreSet fibre_geometry(const FiberSet& fibers) {
  fibres::FibreSet g;
  g.points = fibers.points;
  g.offsets = fibers.offsets;
  g.radius = fibers.radius;
  return g;
}

bool grid_names_its_fibres(const volume::Grid& grid) { return grid.metadata().count("generator") != 0; }

FiberSet fibers_of_grid(const volume::Grid& grid, const std::string& what, ProgressSink& progress) {
  const auto meta = grid.metadata();
  const auto it = meta.find("generator");
  if (it == meta.end())
    fail("{}: the grid does not name its fibres (no cloth spec in its metadata: not written by weft gen)", what);
  const ClothSpec spec = resolve(cloth_spec_from_json(it->second, what + " (metadata 'generator')"));
  FiberSet fibers = generate_fibers(spec, cloth_centerlines(spec), progress);
  // The regenerated fibres must be the voxelized ones: same volume as recorded at generation.
  const auto v = meta.find("fiber_volume_mm3");
  if (v != meta.end()) {
    const std::optional<double> recorded = parse_number(v->second);
    const double now = fibers.volume();
    if (!recorded || std::abs(now - *recorded) > 1e-9 * std::abs(*recorded))
      fail("{}: the fibres regenerated from its cloth spec ({} mm^3) are not the ones voxelized ({} mm^3)", what, now,
           v->second);
  }
  // And they must lie where the grid's voxels are: a grid moved or re-indexed after weft gen keeps
  // its provenance, and its fibres would then miss it (T_fibre = 1, silently). The voxelizer marks
  // every voxel a fibre's cross-section touches, so each face of the fibres' box (points ± radius)
  // is within a voxel of the active box's; two voxels are allowed.
  const volume::IndexBox box = grid.active_bbox();
  if (!box.empty() && fibers.size() > 0) {
    const double h = grid.voxel_size();
    const auto origin = grid.origin();
    std::array<double, 3> lo{HUGE_VAL, HUGE_VAL, HUGE_VAL};
    std::array<double, 3> hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (std::size_t f = 0; f < fibers.size(); ++f) {
      for (std::size_t i = fibers.offsets[f]; i < fibers.offsets[f + 1]; ++i) {
        for (std::size_t a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], fibers.points[i][a] - fibers.radius[f]);
          hi[a] = std::max(hi[a], fibers.points[i][a] + fibers.radius[f]);
        }
      }
    }
    for (std::size_t a = 0; a < 3; ++a) {
      const double glo = origin[a] + h * box.min[a];
      const double ghi = origin[a] + h * (box.max[a] + 1.0);
      if (std::abs(lo[a] - glo) > 2.0 * h || std::abs(hi[a] - ghi) > 2.0 * h)
        fail(
            "{}: the fibres regenerated from its cloth spec span [{:.6g}, {:.6g}] along {} but the grid's active "
            "voxels [{:.6g}, {:.6g}]: the grid was moved or edited after weft gen, so its fibres are not its voxels",
            what, lo[a], hi[a], "xyz"[a], glo, ghi);
    }
  }
  return fibers;
}

}  // namespace weft::cloth
