#include "data_gen/cloth/fibers.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace weft::cloth {
namespace {
double distance(const Point3& a, const Point3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
}  // namespace

void FiberSet::add(const std::vector<Point3>& polyline, double r, std::int32_t yarn_id, std::int32_t ply_id,
                   std::int32_t fiber_id, FiberKind k) {
  if (polyline.size() < 2) return;
  points.insert(points.end(), polyline.begin(), polyline.end());
  offsets.push_back(points.size());
  radius.push_back(r);
  yarn.push_back(yarn_id);
  ply.push_back(ply_id);
  fiber.push_back(fiber_id);
  kind.push_back(k);
}

void FiberSet::append(const FiberSet& source) {
  const FiberSet copy = &source == this ? source : FiberSet{};
  const FiberSet& other = &source == this ? copy : source;
  const std::uint64_t base = points.size();
  points.insert(points.end(), other.points.begin(), other.points.end());
  for (std::size_t i = 1; i < other.offsets.size(); ++i) offsets.push_back(base + other.offsets[i]);
  radius.insert(radius.end(), other.radius.begin(), other.radius.end());
  yarn.insert(yarn.end(), other.yarn.begin(), other.yarn.end());
  ply.insert(ply.end(), other.ply.begin(), other.ply.end());
  fiber.insert(fiber.end(), other.fiber.begin(), other.fiber.end());
  kind.insert(kind.end(), other.kind.begin(), other.kind.end());
  loops += other.loops;
}

std::size_t FiberSet::count(FiberKind k) const {
  return static_cast<std::size_t>(std::count(kind.begin(), kind.end(), k));
}

double FiberSet::volume() const {
  double total = 0.0;
  for (std::size_t f = 0; f < size(); ++f) {
    double len = 0.0;
    for (std::uint64_t i = offsets[f] + 1; i < offsets[f + 1]; ++i) len += distance(points[i - 1], points[i]);
    total += len * std::numbers::pi * radius[f] * radius[f];
  }
  return total;
}

double FiberSet::length() const {
  double len = 0.0;
  for (std::size_t f = 0; f < size(); ++f) {
    for (std::uint64_t i = offsets[f] + 1; i < offsets[f + 1]; ++i) len += distance(points[i - 1], points[i]);
  }
  return len;
}

double curve_length(const Curve& curve) {
  double len = 0.0;
  for (std::size_t i = 1; i < curve.points.size(); ++i) len += distance(curve.points[i - 1], curve.points[i]);
  if (curve.closed && curve.points.size() > 1) len += distance(curve.points.back(), curve.points.front());
  return len;
}

std::vector<Curve> fiber_curves(const FiberSet& fibers) {
  std::vector<Curve> out(fibers.size());
  for (std::size_t f = 0; f < fibers.size(); ++f) {
    out[f].points.assign(fibers.points.begin() + static_cast<std::ptrdiff_t>(fibers.offsets[f]),
                         fibers.points.begin() + static_cast<std::ptrdiff_t>(fibers.offsets[f + 1]));
  }
  return out;
}

}  // namespace weft::cloth
