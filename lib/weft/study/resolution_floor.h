#pragma once
/// @file
/// @brief The resolution floor of a coarsening factor (docs/render.md §6e, "The resolution
/// floor"): the fine grid's own images smoothed over one coarse block's footprint on the film,
/// judged with the candidates' estimator. What a coarse representation loses to its block size
/// alone, whatever its law, so a candidate's bias can be read against it.

#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "weft/render/image.h"
#include "weft/render/scene.h"
#include "weft/study/bias_scales.h"

namespace weft::study {

/// @brief Pixels per side of a cube of edge `block` (world units) centred at `centre`, seen by
/// `camera` face-on at its distance: block / (2 d tan(fov/2) / height), the pinhole's pixel
/// pitch at distance d. Obliquity is not counted (a tilted block projects wider along the
/// tilt). Throws weft::Error for block ≤ 0 or a centre at the camera.
[[nodiscard]] double block_footprint_pixels(const render::CameraDesc& camera, const render::Vec3& centre, double block);

/// @brief `image` (and its variances) convolved with the separable tent of half-width
/// `footprint` pixels, w(d) ∝ max(0, 1 − |d|/footprint) at integer offsets d: a box of the
/// footprint's width averaged over every phase of the box against the pixels (a block edge falls
/// anywhere on the film). Edges repeat their last pixel. Footprint ≤ 1 is the identity. Throws
/// weft::Error for a footprint that is not finite.
[[nodiscard]] render::Image smooth_over_footprint(const render::Image& image, double footprint);

/// The floor at one factor: the footprint used and the bias of the smoothed fine images against
/// the reference at every image scale (bias_scales.h), over the cloth's pixels.
struct ResolutionFloor {
  int factor = 1;
  double footprint = 1.0;  ///< pixels per block side
  ScaleBias scales;        ///< blocks[0] is 1 px: the floor of the candidates' cloth_bias
};

/// @brief The floor of each factor of `factors` with one block of `factor` · `voxel` world units
/// at `centre`: bias_by_scale of smooth(A), smooth(B) against R over `mask`. A and B are the
/// fine grid's two images (independent seeds); smoothing both with one kernel keeps them
/// independent and alike, so the estimator of bias_estimate.h applies unchanged.
[[nodiscard]] std::vector<ResolutionFloor> resolution_floors(
    const render::Image& a, const render::Image& b, const render::Image& reference, const std::vector<bool>& mask,
    const render::CameraDesc& camera, const render::Vec3& centre, double voxel, const std::vector<int>& factors);

/// {"factor", "footprint_px", "scales": scale_bias_json}; and back.
[[nodiscard]] nlohmann::json resolution_floor_json(const ResolutionFloor& f);
[[nodiscard]] ResolutionFloor resolution_floor_from_json(const nlohmann::json& j);

}  // namespace weft::study
