#include "weft/volume/voxel_rule.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/provenance.h"

namespace weft::volume {

std::string to_string(VoxelRule rule) { return rule == VoxelRule::linear ? "linear" : "opaque"; }

VoxelRule parse_voxel_rule(const std::string& text) {
  if (text == "linear") return VoxelRule::linear;
  if (text == "opaque") return VoxelRule::opaque;
  fail("voxel rule '{}' is not one of linear, opaque", text);
}

Grid extinction_grid(const Grid& concentration, double sigma, VoxelRule rule) {
  require_positive("voxel rule: sigma", sigma);
  const double h = concentration.voxel_size();
  const double k = rule == VoxelRule::linear ? sigma : std::max(sigma, 1.0 / h);
  // The floor makes a full voxel's optical depth across one voxel −max(σh, 1)·ln(floor) ≥ 13.8.
  const double c_max = 1.0 - kOpaqueFloor;
  openvdb::FloatGrid::Ptr out = deep_copy(concentration);
  for (auto it = out->tree().beginValueOn(); it; ++it) {
    const double c = static_cast<double>(*it);
    if (rule == VoxelRule::opaque && !(c >= 0.0 && c <= 1.0 + 1e-6))
      fail("voxel rule opaque: grid '{}' holds a concentration {} outside [0, 1]", concentration.name(), c);
    const double mu = rule == VoxelRule::linear ? k * c : -k * std::log1p(-std::min(c, c_max));
    it.setValue(static_cast<float>(mu));
  }
  Grid g = wrap_openvdb(out);
  // Both keys: the copy keeps the source's "weft:value_kind" = concentration, which
  // read_provenance prefers; left so, the grid of μ would be multiplied by σ again.
  g.set_metadata("value_kind", "extinction");
  Provenance kind;
  kind.value_kind = "extinction";
  write_provenance(g, kind);
  g.set_metadata("weft:voxel_rule", to_string(rule));
  return g;
}

}  // namespace weft::volume
