#pragma once
/// @file
/// @brief One realization's work unit in `simulate`: its medium generated and traced, every
/// quantity's free paths tallied, and the result as bytes that cross ranks (dist::run_units).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "data_gen/media2d/disk_grid.h"
#include "data_gen/media2d/simulation.h"
#include "data_gen/media2d/tally.h"
#include "weft/core/rng.h"
#include "weft/dist/distributed.h"

namespace weft::media2d {

struct RealizationOut {
  std::vector<Tally> theta;
  std::optional<Tally> iso;
  std::optional<Tally> scatterer;
  std::vector<Tally> boundary;
  std::size_t perturbed = 0;
  std::size_t count = 0;
};

/// MessagePack: integers and doubles round-trip exactly, so the reduction on rank 0 sees the same
/// numbers as in one process.
[[nodiscard]] dist::Bytes encode(const RealizationOut& r);
[[nodiscard]] RealizationOut decode(const dist::Bytes& b);

// Work unit of (η index, realization); the low 4 bits select the stream's purpose.
[[nodiscard]] std::uint64_t unit_key(std::size_t eta_index, std::size_t realization);

/// A source point on the line x = 0 (`on_boundary_line`) or anywhere, in the void between disks.
[[nodiscard]] Point2 source_origin(const DiskGrid& grid, Pcg32& rng, bool on_boundary_line);
/// The unit direction at `theta_deg` from +x.
[[nodiscard]] Point2 direction_deg(double theta_deg);

/// Realization `j` of η = spec.etas[e]: generated and traced (its structure statistics are a unit
/// of their own, realization_structure.h).
[[nodiscard]] RealizationOut trace_realization(const SimulationSpec& spec, std::size_t e, std::size_t j);

}  // namespace weft::media2d
