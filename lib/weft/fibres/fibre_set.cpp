#include "weft/fibres/fibre_set.h"

#include <cmath>
#include <numbers>

#include "weft/core/error.h"

namespace weft::fibres {

void FibreSet::add(const std::vector<Point3>& polyline, double r) {
  if (polyline.empty()) return;
  points.insert(points.end(), polyline.begin(), polyline.end());
  offsets.push_back(points.size());
  radius.push_back(r);
}

void FibreSet::check(const char* what) const {
  if (offsets.size() != radius.size() + 1 || offsets.front() != 0 || offsets.back() != points.size())
    fail("{}: fibre offsets do not match {} fibres of {} points", what, radius.size(), points.size());
  for (std::size_t f = 0; f < size(); ++f) {
    if (!(radius[f] > 0.0) || !std::isfinite(radius[f]))
      fail("{}: fibre {}: radius must be finite and > 0, got {}", what, f, radius[f]);
    if (offsets[f + 1] <= offsets[f]) fail("{}: fibre {} has no points", what, f);
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (double c : points[i]) {
      if (!std::isfinite(c)) fail("{}: point {} is not finite", what, i);
    }
  }
}

double FibreSet::volume() const {
  double v = 0.0;
  for (std::size_t f = 0; f < size(); ++f) {
    double len = 0.0;
    for (std::uint64_t i = offsets[f] + 1; i < offsets[f + 1]; ++i) {
      const auto& a = points[i - 1];
      const auto& b = points[i];
      len += std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    }
    v += std::numbers::pi * radius[f] * radius[f] * len;
  }
  return v;
}

}  // namespace weft::fibres
