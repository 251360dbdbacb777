#pragma once
/// @file
/// @brief The checks of a beam request that `weft measure`, `weft validate` and the Python module
/// share (one rule, the caller's words: docs/python.md "One set of checks").

#include <array>
#include <vector>

#include "weft/core/front_end.h"
#include "weft/volume/beam.h"
#include "weft/volume/lattice.h"

namespace weft::volume {

/// @brief Refuses rays_per_column < 1, and more rays per column or jitter when every beam runs
/// along an axis: the rays of one voxel column then cross the same voxels, so they cannot change
/// T or its error and would only multiply the time. Throws weft::Error naming the option as
/// `asker` writes it.
void check_rays_per_column(const std::vector<std::array<double, 3>>& directions, int rays_per_column, bool jitter,
                           FrontEnd asker);

/// @brief Refuses full chords when every beam runs along an axis: an axis beam's rays all cross
/// the whole box, so the option would change nothing. Throws weft::Error naming the option as
/// `asker` writes it.
void check_full_chords(const std::vector<std::array<double, 3>>& directions, bool full_chords, FrontEnd asker);

/// @brief Refuses full chords on a beam over `box` (cells of width `cell`) whose lattice would keep
/// no ray: no ray crosses the box from face to opposite face (two faces tie, as across a square
/// face at exactly 45°) or fewer than one lattice ray's share does (BeamLattice::full_chord_problem).
/// Cheap (no ray is traced): front ends call it for every beam before the first is traced.
void check_full_chord_rays(const WorldBox& box, double cell, const BeamSpec& spec, FrontEnd asker);

enum class BeamMethod;

/// @brief Refuses the streaming method for an oblique beam: it walks whole voxel columns along an
/// axis (docs/validate.md "Ground truth"), so it has no oblique form. Throws weft::Error naming
/// the method option and the direction as `asker` writes them, before any beam runs.
void check_beam_method(BeamMethod method, const std::vector<std::array<double, 3>>& directions, FrontEnd asker);

}  // namespace weft::volume
