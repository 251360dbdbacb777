#include "data_gen/cloth/provenance.h"

#include <cmath>
#include <numbers>

#include "weft/core/error.h"

namespace weft::cloth {

std::optional<ClothSpec> spec_of_grid(const volume::Grid& grid) {
  const auto metadata = grid.metadata();
  const auto it = metadata.find("generator");
  if (it == metadata.end()) return std::nullopt;
  return cloth_spec_from_json(it->second, "grid '" + grid.name() + "' metadata 'generator'");
}

double fiber_sigma(const ClothSpec& spec) {
  const double warp = spec.warp_yarn.fiber_radius;
  const double weft = spec.weft_yarn.fiber_radius;
  // Knit and imported cloth use the warp yarn only.
  const bool woven = spec.pattern != "stockinette" && spec.pattern != "import";
  if (woven && warp != weft)
    fail("fibre radius differs between warp ({} mm) and weft ({} mm): no single sigma; give sigma explicitly", warp,
         weft);
  require_positive("fiber_radius", warp);
  return 2.0 / (std::numbers::pi * warp);
}

}  // namespace weft::cloth
