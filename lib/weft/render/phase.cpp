#include "weft/render/phase.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "weft/render/frame.h"

namespace weft::render {

double hg(double g, double cos_theta) {
  const double d = 1.0 + g * g - 2.0 * g * cos_theta;
  return (1.0 - g * g) / (4.0 * std::numbers::pi * d * std::sqrt(d));
}

Vec3 sample_hg(double g, const Vec3& dir, Pcg32& rng) {
  const double u = rng.uniform();
  double cos_theta = 0.0;
  if (std::abs(g) < 1e-4) {
    cos_theta = 1.0 - 2.0 * u;
  } else {
    const double q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    cos_theta = std::clamp((1.0 + g * g - q * q) / (2.0 * g), -1.0, 1.0);
  }
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  const double phi = 2.0 * std::numbers::pi * rng.uniform();
  return from_frame(dir, sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta).normalized();
}

}  // namespace weft::render
