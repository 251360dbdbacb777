#pragma once
/// @file
/// @brief The structure statistics of one realization as a work unit of `simulate` of its own:
/// they cost more than tracing a realization (CGAL's periodic Delaunay triangulation), so a
/// realization that also measured them held the other threads up (docs/sim2d.md).

#include <cstddef>

#include "data_gen/media2d/simulation.h"
#include "data_gen/media2d/structure.h"
#include "weft/dist/distributed.h"

namespace weft::media2d {

/// The structure statistics of realization `j` of η = spec.etas[e] (the same medium as
/// `realization(spec, e, j)`), or of a stand-in of spec.structure_max_points particles from the
/// same generator when the medium has more.
[[nodiscard]] StructureStats realization_structure(const SimulationSpec& spec, std::size_t e, std::size_t j);

/// MessagePack, exact for integers and doubles (as the realizations' tallies).
[[nodiscard]] dist::Bytes encode(const StructureStats& s);
[[nodiscard]] StructureStats decode_structure(const dist::Bytes& b);

}  // namespace weft::media2d
