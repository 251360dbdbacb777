#include "weft/render/camera.h"

#include <cmath>
#include <numbers>

#include "weft/render/frame.h"

namespace weft::render {

Camera::Camera(const CameraDesc& d) : position(d.position), width(d.width), height(d.height) {
  // unit_vector, not normalized(): a look_at 1e-300 from the position or a tiny "up" is a valid
  // direction whose squared length underflows.
  forward = unit_vector(d.look_at - d.position);
  right = unit_vector(forward.cross(d.up));
  up = right.cross(forward);
  tan_half = std::tan(0.5 * d.fov_deg * std::numbers::pi / 180.0);
  aspect = static_cast<double>(d.width) / d.height;
  lens_radius = d.aperture_radius;
  focus = d.focus_distance > 0.0 ? d.focus_distance : (d.look_at - d.position).norm();
}

void Camera::generate(double fx, double fy, Pcg32& rng, Vec3& o, Vec3& dir) const {
  const double sx = (2.0 * fx / width - 1.0) * tan_half * aspect;
  const double sy = (1.0 - 2.0 * fy / height) * tan_half;
  dir = (forward + sx * right + sy * up).normalized();
  o = position;
  if (lens_radius > 0.0) {
    const Vec3 focal = position + dir * (focus / dir.dot(forward));
    const double r = lens_radius * std::sqrt(rng.uniform());
    const double phi = 2.0 * std::numbers::pi * rng.uniform();
    o = position + r * std::cos(phi) * right + r * std::sin(phi) * up;
    dir = (focal - o).normalized();
  }
}

}  // namespace weft::render
