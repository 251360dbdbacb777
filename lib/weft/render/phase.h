#pragma once
/// @file
/// @brief Phase functions of the media: Henyey–Greenstein, evaluated and sampled (docs/render.md §2).

#include <string_view>

#include "weft/core/rng.h"
#include "weft/render/scene.h"

namespace weft::render {

/// Largest |g| a medium takes. The HG lobe's width is about 1 − |g| radians; directions in double
/// precision resolve angles down to about 1e-8 rad (a cosine's rounding of 1e-16), so a lobe
/// narrower than that is evaluated from rounding and a path's MIS weights with it (a white furnace
/// at g = 1 − 1e-8 rendered 0.91). At 1 − 1e-6 the lobe is 100× wider than that resolution.
inline constexpr double kMaxAbsG = 1.0 - 1e-6;

/// Throws weft::Error "<where>: 'g' must be in [-0.999999, 0.999999] …" for |g| > kMaxAbsG or NaN.
void check_phase_g(double g, std::string_view where);

/// Henyey–Greenstein phase function of cos θ between the propagation directions before and after.
/// Its denominator 1 + g² − 2g cos θ is computed as (1 − g)² + 2g(1 − cos θ) for g ≥ 0 (and the
/// mirror form for g < 0), with no cancellation where the lobe peaks.
[[nodiscard]] double hg(double g, double cos_theta);

/// Samples a direction from HG around `dir` (exact inversion); the pdf equals hg(). 1 − cos θ and
/// 1 + cos θ come from closed forms without cancellation (docs/render.md §2), so a narrow lobe's
/// small angles are drawn, not rounded to 0.
[[nodiscard]] Vec3 sample_hg(double g, const Vec3& dir, Pcg32& rng);

}  // namespace weft::render
