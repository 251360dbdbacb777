#pragma once
/// @file
/// @brief Exact ray–capsule intersection and a bounding volume hierarchy over the capsules of a
/// FibreSet, in double precision: every capsule a ray meets, as its [entry, exit] interval
/// (docs/validate.md §Fibre ground truth, "why not Embree").

#include <array>
#include <cstdint>
#include <vector>

#include "weft/fibres/fibre_set.h"

namespace weft::fibres {

/// An interval [t0, t1] of a ray's parameter.
using Interval = std::array<double, 2>;

/// The interval of the ray o + t·d (d of unit length) inside the capsule of radius r around
/// segment a→b (a sphere when a = b), or false when the ray misses it (tangent rays count as
/// hits of zero length). The capsule is convex, so its intersection with the line is one
/// interval: the hull of the line's intervals in the finite cylinder and the two end spheres.
bool ray_capsule(const Point3& o, const Point3& d, const Point3& a, const Point3& b, double r, Interval& out);

/// A BVH over the segments (capsules) of a FibreSet: median splits on the longest axis of the
/// segment centres, ≤ 4 capsules per leaf; built once, read-only and shareable between threads.
class CapsuleIndex {
 public:
  explicit CapsuleIndex(const FibreSet& fibres);

  /// Appends to `out` the interval of every capsule that the ray o + t·d (unit d) meets, clipped
  /// to [tmin, tmax] (those entirely outside are skipped), in a fixed order.
  void intersect(const Point3& o, const Point3& d, double tmin, double tmax, std::vector<Interval>& out) const;

  [[nodiscard]] std::size_t capsule_count() const { return caps_.size(); }
  /// Bounds of every capsule (empty index: lo > hi).
  [[nodiscard]] const Point3& lo() const { return lo_; }
  [[nodiscard]] const Point3& hi() const { return hi_; }

 private:
  struct Capsule {
    Point3 a;
    Point3 b;
    double r;
  };
  struct Node {
    Point3 lo;
    Point3 hi;
    std::uint32_t first;  ///< leaf: first capsule; inner: index of the right child (left is next)
    std::uint32_t count;  ///< capsules in a leaf, 0 for an inner node
  };
  std::uint32_t build(std::vector<std::uint32_t>& order, std::uint32_t begin, std::uint32_t end,
                      const std::vector<Point3>& centre, const std::vector<Capsule>& input);
  std::vector<Capsule> caps_;
  std::vector<Node> nodes_;
  Point3 lo_{1.0, 1.0, 1.0};
  Point3 hi_{0.0, 0.0, 0.0};
};

}  // namespace weft::fibres
