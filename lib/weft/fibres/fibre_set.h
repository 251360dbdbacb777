#pragma once
/// @file
/// @brief Fibre geometry for exact ray intersection: open polylines with a radius each, the
/// solid being the union of the capsules (a cylinder per segment with spheres at its ends)
/// swept by a sphere of that radius along the polyline (docs/validate.md §Fibre ground truth).

#include <array>
#include <cstdint>
#include <vector>

#include "weft/curves/curve_io.h"

namespace weft::fibres {

using Point3 = curves::Point3;

/// @brief Polyline i uses points[offsets[i] .. offsets[i+1]) with radius[i] (same layout as the
/// cloth generator's fibres, without their yarn/ply ids).
struct FibreSet {
  std::vector<Point3> points;
  std::vector<std::uint64_t> offsets{0};
  std::vector<double> radius;

  [[nodiscard]] std::size_t size() const { return radius.size(); }
  /// Appends a polyline of ≥ 1 point (one point: a sphere).
  void add(const std::vector<Point3>& polyline, double r);
  /// Throws weft::Error when a radius is not finite and > 0, a point is not finite, or the
  /// offsets are inconsistent; `what` names the source.
  void check(const char* what) const;
  /// Σ over fibres of polyline length × π r² (caps not counted, as the voxelizer).
  [[nodiscard]] double volume() const;
};

}  // namespace weft::fibres
