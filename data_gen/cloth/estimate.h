#pragma once
/// @file
/// @brief What a cloth will cost, from its centrelines alone: fibres, active voxels and memory
/// estimated before any fibre is made, so a wrong scale or a huge weave is refused in
/// milliseconds instead of after minutes of generation.

#include <cstdint>
#include <string>

#include "data_gen/cloth/fibers.h"
#include "data_gen/cloth/spec.h"
#include "weft/core/front_end.h"

namespace weft::cloth {

/// @brief Estimates of one build (`weft gen`): what generation, voxelization and the fibre
/// file will hold. Within 2× of the measured figures for the built-in weaves, knits and long
/// imported yarns, and for dense loops, far loops and high hairs (tests/unit/cloth/estimate_test.cpp).
struct ClothEstimate {
  double fiber_length = 0.0;           ///< mm of fibre (regular fibres follow their helices; flyaways)
  std::uint64_t fibers = 0;            ///< polylines
  std::uint64_t fiber_points = 0;      ///< polyline points
  std::uint64_t fiber_bytes = 0;       ///< the FiberSet in memory
  std::uint64_t active_voxels = 0;     ///< voxels of the grid
  std::uint64_t leaves = 0;            ///< 8³ leaf nodes of the grid
  std::uint64_t grid_bytes = 0;        ///< the OpenVDB tree (what its memUsage() reports)
  std::uint64_t transient_bytes = 0;   ///< largest short-lived buffer: voxelizer bins, the VTK copy or the plan
  std::uint64_t voxelizer_bytes = 0;   ///< the voxelizer's bins (transient_bytes' first part)
  std::uint64_t vtk_bytes = 0;         ///< the VTK copy of the fibres for fibers.vtp (its second part)
  std::uint64_t peak_bytes = 0;        ///< fibres + grid + transient
  std::uint64_t loops = 0;             ///< loop flyaways drawn (they reshape regular fibres and add none)
  std::uint64_t plan_bytes = 0;        ///< the random part held while points are made (yarn_cost): stations, flyaways
  std::uint64_t loop_bytes = 0;        ///< the loops' share of plan_bytes
  std::uint64_t loop_reach_bytes = 0;  ///< grid leaves along the loops' paths beyond the yarn envelope
  std::uint64_t hair_bytes = 0;        ///< hairs: their fibres, points and the grid leaves along their paths
  double steps = 0.0;                  ///< steps of making the fibres (yarn_cost: points made, loops blended into them)
  double loop_steps = 0.0;             ///< the loops' share of steps
  double loop_density = 0.0;           ///< the largest loop_density of the yarns (for messages)
  double loop_coverage = 0.0;          ///< the largest loop_coverage of the yarns: loops over a fibre point
  /// A count past 64 bits or a length past double's range (a scale off by 10¹⁰⁰): the counts
  /// above are then saturated, not figures, and check_budget refuses the cloth saying so.
  bool overflow = false;
};

/// @brief The estimate for a resolved spec and its centrelines (in mm).
///
/// Fibres: per yarn of centreline length L, ply_count × (fiber_count × (⌈L/step⌉ + 1) points)
/// plus hair_density·L hairs of ⌈hair_length/step⌉ + 1 points, and what generating them holds and
/// spends (yarn_cost, yarn.h: the plan of stations and flyaways, the steps). Active voxels: each ply is a
/// Boolean model of fibres (Poisson in its cross-section) inside a disc of the ply's area; with
/// a(r) = πr² + 1.5πhr + 1.5h² the mean area a fibre of radius r covers in voxels of edge h
/// (Minkowski sum of the fibre section and a randomly oriented cube's projection: mean area
/// 1.5h², mean perimeter 1.5πh), a ply of n fibres covers A_d·(1 − exp(−n·a(r)/A_d)) per unit
/// length, A_d = a(ρ + r) its dilated disc. Leaves: the yarn as one tube of its envelope radius
/// in cells of 8h. Flyaways add their paths to the length, voxels and leaves: hairs their rise
/// and turn, loops their excursions beyond the fibre's radius, 1 − e^(−c) per fibre and migration
/// period (c = loop_coverage; docs/cloth.md "Estimate before spending"). O(centreline points),
/// nothing allocated.
ClothEstimate estimate_cloth(const ClothSpec& spec, const CurveSet& centerlines);

/// @brief The estimate of a build that stops at the fibres (`weft gen --write` without `grid`):
/// no grid, no voxelizer bins; the peak is the fibres and the larger of the plan and the VTK copy.
[[nodiscard]] ClothEstimate without_grid(ClothEstimate e);

/// @brief The estimate of a woven or knitted spec before its centrelines exist (they alone take
/// 3 GB for 2000×2000 yarns): specs up to 60×60 yarns are estimated on their centrelines, larger
/// ones on a 60×60 probe (a multiple of every pattern repeat) scaled by the yarn-count product,
/// which both the total yarn length and the crossings grow with. Imports: use the overload above
/// on the file's curves.
ClothEstimate estimate_cloth(const ClothSpec& spec);

/// The estimate on one line, for messages and the summary.
std::string describe(const ClothEstimate& e);
/// describe with the peak as given (`peak`: a budget message prints it apart from the budget).
std::string describe(const ClothEstimate& e, const std::string& peak);

/// Throws weft::Error (naming the estimate and the budget, and the options that set them in the
/// words of `asker`: `--max-memory` or `max_memory_mb=`) when e.peak_bytes exceeds `budget_bytes`
/// (0 = default_memory_budget()), when e.steps exceed volume::kMaxPassSteps (the work bound of
/// every pass), or when the estimate overflowed. When loops, loop radii or hairs are more than half
/// of the bytes or steps, the message names those yarn parameters (`--set loop_density=1e+08`).
/// The message starts with `subject` (an import names its file and scale); with a `config` (the
/// cloth.json the values came from) the scale advice names its keys beside the options.
void check_budget(const ClothEstimate& e, std::uint64_t budget_bytes, FrontEnd asker = FrontEnd::cli,
                  const std::string& subject = "cloth", const std::string& config = "");

}  // namespace weft::cloth
