#pragma once
/// @file
/// @brief The OpenVDB side of weft::volume::Grid. Include only from .cpp files.

#include <openvdb/openvdb.h>

#include "weft/volume/grid.h"

namespace weft::volume {

struct Grid::Impl {
  openvdb::FloatGrid::Ptr grid;
};

/// Wraps an existing OpenVDB grid (shares it); checks it has a uniform-scale transform.
Grid make_grid(std::shared_ptr<Grid::Impl> impl);
Grid wrap_openvdb(openvdb::FloatGrid::Ptr grid);

/// Calls openvdb::initialize() once per process.
void ensure_openvdb_initialized();

}  // namespace weft::volume
