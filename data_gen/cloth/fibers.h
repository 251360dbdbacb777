#pragma once
/// @file
/// @brief Curves (yarn centrelines) and fibres (polylines with a radius and yarn/ply/fibre ids).

#include <array>
#include <cstdint>
#include <vector>

#include "weft/curves/curve_io.h"

namespace weft::cloth {

using Point3 = curves::Point3;
/// @brief A polyline (weft/curves): the cloth generator and the curve files share one type.
using Curve = curves::Curve;

/// @brief Yarn centrelines with the yarn preset each one uses (0 = warp, 1 = weft).
struct CurveSet {
  std::vector<Curve> curves;
  std::vector<int> direction;  ///< per curve: 0 warp (also knit and imported), 1 weft
};

/// What kind of fibre a polyline is (Zhao et al. 2016, §4.1–4.2).
enum class FiberKind : std::int32_t { regular = 0, loop = 1, hair = 2 };

/// @brief Fibres as open polylines with a radius each, in mm.
///
/// Polyline i uses points[offsets[i] .. offsets[i+1]); every per-fibre vector has one entry per
/// polyline. A fibre's volume is its length × π r² (caps not counted).
struct FiberSet {
  std::vector<Point3> points;
  std::vector<std::uint64_t> offsets{0};
  std::vector<double> radius;
  std::vector<std::int32_t> yarn;   ///< index of the yarn (centreline) the fibre belongs to
  std::vector<std::int32_t> ply;    ///< ply within the yarn
  std::vector<std::int32_t> fiber;  ///< fibre within the ply (hairs numbered after the regular fibres)
  std::vector<FiberKind> kind;
  /// Loop flyaways drawn: each reshapes one of the regular fibres (those of kind loop), none adds one.
  std::uint64_t loops = 0;

  [[nodiscard]] std::size_t size() const { return radius.size(); }
  /// Appends one polyline; ignored when it has fewer than two points.
  void add(const std::vector<Point3>& polyline, double r, std::int32_t yarn_id, std::int32_t ply_id,
           std::int32_t fiber_id, FiberKind k);
  /// Appends all fibres of `other` (ids kept).
  void append(const FiberSet& other);
  /// Σ over fibres of polyline length × π r² (mm³).
  [[nodiscard]] double volume() const;
  /// Total polyline length (mm).
  [[nodiscard]] double length() const;
  /// Number of fibres of kind `k`.
  [[nodiscard]] std::size_t count(FiberKind k) const;
  /// Number of line segments over all fibres.
  [[nodiscard]] std::uint64_t segment_count() const { return points.size() - size(); }
};

/// Length of a polyline (closing segment included when closed).
double curve_length(const Curve& curve);

/// The fibres as open curves (for curves::write_bcc / write_obj_curves).
std::vector<Curve> fiber_curves(const FiberSet& fibers);

}  // namespace weft::cloth
