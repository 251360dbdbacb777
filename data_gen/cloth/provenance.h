#pragma once
/// @file
/// @brief What a generated grid's provenance says about the physics: the cloth spec that made it
/// and the extinction cross-section of its fibres.

#include <optional>

#include "data_gen/cloth/spec.h"
#include "weft/volume/grid.h"

namespace weft::cloth {

/// The spec `weft gen` recorded in the grid's "generator" metadata; nullopt when the grid has
/// none (not made by weft gen). Throws weft::Error when the metadata is there but unreadable.
[[nodiscard]] std::optional<ClothSpec> spec_of_grid(const volume::Grid& grid);

/// @brief Extinction per unit fibre volume fraction, σ = 2/(π r) [1/mm] for fibres of radius r.
///
/// A cylinder of radius r and length ℓ seen side-on blocks 2rℓ of area for πr²ℓ of volume, so a
/// volume fraction C of such fibres has μ = C·2/(πr) (the σ `weft validate` uses). Throws
/// weft::Error when the warp and weft fibres differ in radius (one σ cannot describe both).
[[nodiscard]] double fiber_sigma(const ClothSpec& spec);

}  // namespace weft::cloth
