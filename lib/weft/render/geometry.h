#pragma once
/// @file
/// @brief The Embree side of a scene: shapes, ray queries and area sampling (internal to render;
/// no Embree type appears here).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/rng.h"
#include "weft/render/mesh.h"
#include "weft/render/scene.h"

namespace weft::render {

/// A shape as the integrator sees it: indices into the scene's runtime tables.
struct ShapeInfo {
  ShapeKind kind = ShapeKind::sphere;
  int material = -1;  ///< -1: emitter only (absorbs what it does not emit)
  bool null_material = false;
  int interior = -1;  ///< medium index, -1 = vacuum
  int exterior = -1;
  Rgb emission{0, 0, 0};
  Vec3 center{0, 0, 0};
  double radius = 0.0;
  TriangleMesh mesh;             ///< world-space triangles (not for spheres)
  std::vector<Vec3> normals;     ///< unit normal of each triangle by winding (computed once, not per hit)
  std::vector<double> area_cdf;  ///< triangle area CDF for sampling (normalised)
  double area = 0.0;
  std::size_t curve_segments = 0;  ///< curves: round linear segments in the BVH
  Vec3 lo{0, 0, 0};                ///< axis-aligned bounds (a box shape is exactly its bounds)
  Vec3 hi{0, 0, 0};
};

/// What single-precision Embree can trace (docs/render.md §1, "Where Embree's floats are"): every
/// coordinate it is given, relative to its frame, within ±kMaxReach. Its round-linear-curve test
/// squares a discriminant of degree 6 in the lengths it meets (segment, radius, origin); with every
/// length at most the cube's diagonal 2√3·kMaxReach its terms stay below float's 3.4e38 with a
/// margin of 10 (the triangle test, degree 3, would allow 1e12; spheres, degree 2, Embree's own
/// origin limit 1.8e19).
inline constexpr double kMaxReach = 1e5;

/// Ray offsets off a surface, relative to the coordinates in Embree's frame and the scene's size
/// (float hit points: 1e-5 is ~170 float spacings).
inline constexpr double kSpawnOffset = 1e-5;

/// How far from the world origin a scene may lie, in its extents: the double spacing there
/// (2^-52 of the distance, 2.2e-6 extents at 1e10) stays 4.5 times below the smallest ray offset
/// (kSpawnOffset extents). Measured: the slab of tests/unit/render/translation_test.cpp renders
/// the same mean at 8e10 extents and black at 8e11.
inline constexpr double kMaxExtentsAway = 1e10;

/// The one check of kMaxReach, for shapes (after scale and translate, with radii) and the camera:
/// throws weft::Error "<what> <reach> from …" (what: "coordinates reach", "camera.position reaches") when `reach` (the
/// largest |coordinate − frame|) is beyond it.
void require_traceable(double reach, const Vec3& frame, const std::string& what);

struct SurfaceHit {
  double t = 0.0;
  int shape = -1;
  Vec3 p{0, 0, 0};
  Vec3 n{0, 0, 1};  ///< unit geometric normal, outward (sphere) or by winding (meshes)
};

struct AreaSample {
  Vec3 p;
  Vec3 n;
};

/// Shapes in an Embree BVH. Thread-safe queries after construction.
class Geometry {
 public:
  /// `material_index` / `medium_index` map names to runtime indices.
  Geometry(const SceneDesc& scene, const std::map<std::string, int>& material_index,
           const std::map<std::string, int>& medium_index);
  ~Geometry();
  Geometry(const Geometry&) = delete;
  Geometry& operator=(const Geometry&) = delete;

  /// Closest hit with t in (tmin, tmax), or none.
  [[nodiscard]] std::optional<SurfaceHit> intersect(const Vec3& o, const Vec3& d, double tmin, double tmax) const;
  /// Whether anything lies on the ray in (tmin, tmax).
  [[nodiscard]] bool occluded(const Vec3& o, const Vec3& d, double tmin, double tmax) const;
  /// A distance along the ray from `p` in direction `d` (unit) below which the ray cannot hit
  /// any surface, with room for the float arithmetic of the BVH's hit distances (docs/render.md
  /// §1, "Queries a path skips"): 0 when unknown (more than a few shapes, or `p` inside the bounds of a
  /// shape that is not a box or sphere), +inf when the ray misses every shape's bounds.
  [[nodiscard]] double clearance(const Vec3& p, const Vec3& d) const;
  /// The scene is one convex shape (a box or a sphere): intersected in closed form, and a ray
  /// that has just left it through its surface, going outward, hits nothing more.
  [[nodiscard]] bool lone_convex() const { return lone_convex_; }

  [[nodiscard]] const std::vector<ShapeInfo>& shapes() const { return shapes_; }
  /// Uniform point on a shape's surface (pdf 1/area).
  [[nodiscard]] AreaSample sample_area(int shape, Pcg32& rng) const;
  /// Size of the scene's bounding box (for ray offsets).
  [[nodiscard]] double extent() const { return extent_; }
  /// The world point that is Embree's origin (docs/render.md §1, "Where Embree's floats are").
  [[nodiscard]] const Vec3& frame() const { return frame_; }
  /// The largest |coordinate − frame()| of a box, for require_traceable.
  [[nodiscard]] double reach(const Vec3& lo, const Vec3& hi) const;
  /// How far a ray leaving a surface at `p` starts off it (along the normal): kSpawnOffset of the
  /// scene's extent plus p's coordinates in Embree's frame, where its floats round them. The
  /// same at any translation of the scene, since the frame moves with it.
  [[nodiscard]] double spawn_offset(const Vec3& p) const;

 private:
  /// intersect() for a lone box or sphere, in closed form.
  [[nodiscard]] std::optional<SurfaceHit> intersect_lone(const Vec3& o, const Vec3& d, double tmin, double tmax) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<ShapeInfo> shapes_;
  double extent_ = 1.0;
  Vec3 frame_{0, 0, 0};
  bool lone_convex_ = false;
};

}  // namespace weft::render
