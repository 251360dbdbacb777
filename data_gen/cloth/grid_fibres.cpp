#include "data_gen/cloth/grid_fibres.h"

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
  return fibers;
}

}  // namespace weft::cloth
