#pragma once
/// @file
/// @brief The reciprocity check p_Q(t) = T_S(t)/ℓ_S over realizations (Reciprocity, simulation.h).

#include <cstddef>
#include <vector>

#include "data_gen/media2d/simulation.h"
#include "data_gen/media2d/tally.h"

namespace weft::media2d {

/// Checks p_Q = T_S/ℓ_S bin by bin from the source (`source`) and scatterer (`scatterer`) tallies
/// of each realization, on `result`'s grid.
[[nodiscard]] Reciprocity check_reciprocity(const std::vector<const Tally*>& source,
                                            const std::vector<const Tally*>& scatterer, std::size_t samples,
                                            const SimulationResult& result);

}  // namespace weft::media2d
