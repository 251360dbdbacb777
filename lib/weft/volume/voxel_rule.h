#pragma once
/// @file
/// @brief How a voxel's fibre volume fraction C becomes extinction μ (docs/validate.md
/// §Voxelization error): the linear rule μ = σ·C of the default ground truth, or the
/// opaque-fibre rule that converges to the fibres' own T as the voxel shrinks.

#include <string>

#include "weft/volume/grid.h"

namespace weft::volume {

enum class VoxelRule {
  linear,  ///< μ = σ·C (fibres of optical depth ≈ 1 along their mean chord when voxels are small)
  opaque,  ///< μ = −max(σ, 1/h)·ln(1 − C): a Boolean model of opaque fibres inside each voxel
};

[[nodiscard]] std::string to_string(VoxelRule rule);
/// Parses "linear" | "opaque"; throws weft::Error otherwise.
[[nodiscard]] VoxelRule parse_voxel_rule(const std::string& text);

/// The opaque rule reads C as at most 1 − kOpaqueFloor, so a full voxel's transmittance across
/// one voxel edge is at most kOpaqueFloor (finite optical depths keep the beam sums finite).
inline constexpr double kOpaqueFloor = 1e-6;

/// The extinction grid of a concentration grid under `rule` (values μ in 1/length; σ is the
/// grid's σ per unit concentration). The opaque rule, per voxel of edge h:
///   a voxel holding fibre volume fraction C is read as a Boolean model of opaque fibres whose
///   union fills C, so their intensity (fibre volume per volume, overlaps counted) is −ln(1 − C)
///   and T across the voxel is (1 − C)^{σh}; and opaque material filling C of a voxel blocks at
///   least C of the rays crossing it (its shadow is at least its volume over h), T ≤ (1 − C)^1.
///   Both hold with the exponent max(σh, 1): μ = −max(σ, 1/h)·ln(1 − C), = σC to first order
///   in C for large voxels, opaque (T ≤ kOpaqueFloor per voxel) where C = 1.
/// Throws weft::Error for σ ≤ 0 or a value outside [0, 1] under the opaque rule.
[[nodiscard]] Grid extinction_grid(const Grid& concentration, double sigma, VoxelRule rule);

}  // namespace weft::volume
