#pragma once
// Hand-built grids shared by the fit tests.
#include <string>

#include "weft/fit/validation.h"
#include "weft/volume/grid.h"

namespace weft::fit::test {

/// A box of nx x ny x nz voxels of `value` from the origin, voxel size h.
inline volume::Grid box_grid(int nx, int ny, int nz, float value, double h = 1.0) {
  volume::Grid g(h);
  g.set_origin({0.0, 0.0, 0.0});
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) g.set_value(i, j, k, value);
  return g;
}

/// 16 x 12 x 6 voxels of h = 0.05 with C = ((7i + 3j + 5k) mod 11)/20: structure on every axis.
inline volume::Grid patterned_grid() {
  volume::Grid g(0.05);
  g.set_origin({0, 0, 0});
  for (int i = 0; i < 16; ++i) {
    for (int j = 0; j < 12; ++j) {
      for (int k = 0; k < 6; ++k) g.set_value(i, j, k, static_cast<float>(((i * 7 + j * 3 + k * 5) % 11) / 20.0));
    }
  }
  return g;
}

/// The spec of validate_patterned: sigma 4, scale 0.2 on every axis, the models of `models`
/// (ModelSelection::parse).
inline ValidationSpec patterned_spec(const std::string& models = "all") {
  ValidationSpec vs;
  vs.sigma = 4.0;
  vs.scale.fill(0.2);
  vs.models = ModelSelection::parse(models);
  return vs;
}

/// validate() of a patterned grid at sigma 4 and scale 0.2 on every axis.
inline Validation validate_patterned(const volume::Grid& g) { return validate(g, patterned_spec()); }

}  // namespace weft::fit::test
