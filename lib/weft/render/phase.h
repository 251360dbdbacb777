#pragma once
/// @file
/// @brief Phase functions of the media: Henyey–Greenstein, evaluated and sampled (docs/render.md §2).

#include "weft/core/rng.h"
#include "weft/render/scene.h"

namespace weft::render {

/// Henyey–Greenstein phase function of cos θ between the propagation directions before and after.
[[nodiscard]] double hg(double g, double cos_theta);

/// Samples a direction from HG around `dir` (exact inversion); the pdf equals hg().
[[nodiscard]] Vec3 sample_hg(double g, const Vec3& dir, Pcg32& rng);

}  // namespace weft::render
