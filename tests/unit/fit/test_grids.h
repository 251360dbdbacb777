#pragma once
// Hand-built grids shared by the fit tests.
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

}  // namespace weft::fit::test
