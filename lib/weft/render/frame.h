#pragma once
/// @file
/// @brief An orthonormal frame around a unit vector, for sampling directions about it.

#include <cmath>
#include <limits>

#include "weft/render/scene.h"

namespace weft::render {

/// `v` / |v| for any finite `v`, the zero vector for zero. A vector whose squared length leaves
/// double's normal range (components below ~1e-154 or above ~1e154: a camera's "up" given as
/// (0, 1e-300, 0)) is first divided by its largest component, since squaring it would give 0 or
/// ∞; in the normal range the result is Eigen's `normalized()` bit for bit, so scenes keep their
/// bytes.
inline Vec3 unit_vector(const Vec3& v) {
  const double z = v.squaredNorm();
  if (z >= std::numeric_limits<double>::min() && z <= std::numeric_limits<double>::max()) return v / std::sqrt(z);
  const double m = v.cwiseAbs().maxCoeff();
  if (!(m > 0.0) || !std::isfinite(m)) return Vec3::Zero();
  const Vec3 w = v / m;
  return w / w.norm();
}

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
