#pragma once
/// @file
/// @brief The checks of a beam request that `weft measure`, `weft validate` and the Python module
/// share (one rule, the caller's words: docs/python.md "One set of checks").

#include <array>
#include <vector>

#include "weft/core/front_end.h"

namespace weft::volume {

/// @brief Refuses rays_per_column < 1, and more rays per column or jitter when every beam runs
/// along an axis: the rays of one voxel column then cross the same voxels, so they cannot change
/// T or its error and would only multiply the time. Throws weft::Error naming the option as
/// `asker` writes it.
void check_rays_per_column(const std::vector<std::array<double, 3>>& directions, int rays_per_column, bool jitter,
                           FrontEnd asker);

enum class BeamMethod;

/// @brief Refuses the streaming method for an oblique beam: it walks whole voxel columns along an
/// axis (docs/validate.md "Ground truth"), so it has no oblique form. Throws weft::Error naming
/// the method option and the direction as `asker` writes them, before any beam runs.
void check_beam_method(BeamMethod method, const std::vector<std::array<double, 3>>& directions, FrontEnd asker);

}  // namespace weft::volume
