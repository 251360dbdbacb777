#pragma once
/// @file
/// @brief The camera: primary rays of a pinhole or thin-lens perspective camera (docs/render.md §1).

#include "weft/core/rng.h"
#include "weft/render/scene.h"

namespace weft::render {

/// A CameraDesc turned into the frame primary rays are generated in.
struct Camera {
  Vec3 position, forward, right, up;
  double tan_half = 0.0, aspect = 1.0, lens_radius = 0.0, focus = 1.0;
  int width = 1, height = 1;

  explicit Camera(const CameraDesc& d);

  /// The ray through film point (fx, fy) in pixels from the top-left corner; a thin lens draws
  /// its lens point from `rng`.
  void generate(double fx, double fy, Pcg32& rng, Vec3& o, Vec3& dir) const;
};

}  // namespace weft::render
