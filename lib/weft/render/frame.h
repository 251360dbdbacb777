#pragma once
/// @file
/// @brief An orthonormal frame around a unit vector, for sampling directions about it.

#include <cmath>

#include "weft/render/scene.h"

namespace weft::render {

/// Completes the unit vector `n` to an orthonormal frame (s, t, n) (Duff et al. 2017).
inline void frame(const Vec3& n, Vec3& s, Vec3& t) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  s = Vec3(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  t = Vec3(b, sign + n.y() * n.y() * a, -n.y());
}

/// The vector with coordinates (x, y, z) in the frame around `n` (z along n).
inline Vec3 from_frame(const Vec3& n, double x, double y, double z) {
  Vec3 s;
  Vec3 t;
  frame(n, s, t);
  return x * s + y * t + z * n;
}

}  // namespace weft::render
