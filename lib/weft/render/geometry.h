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
  /// rectangle: corner + a·u + b·v, a, b in [0, 1]; (a, b) of a point w − corner from the dot
  /// products with u and v through the inverse Gram matrix [uu uv; uv vv]⁻¹ (edges need not be
  /// orthogonal).
  Vec3 corner{0, 0, 0};
  Vec3 u{0, 0, 0};
  Vec3 v{0, 0, 0};
  double gram_uu = 0.0;
  double gram_uv = 0.0;
  double gram_vv = 0.0;
  double extent = 1.0;  ///< (hi − lo).maxCoeff(), for Geometry::spawn_offset
};

/// Ray offsets off a surface, relative to the hit shape's size and the hit point's coordinates in
/// Embree's frame (float hit points: 1e-5 is ~170 float spacings).
inline constexpr double kSpawnOffset = 1e-5;

/// How far a point may lie from the origin its double coordinates are taken from, in extents of
/// the smallest shape: the double spacing there (2^-52 of the distance, 2.2e-6 extents at 1e10)
/// stays 4.5 times below the smallest ray offset (kSpawnOffset extents). It bounds the scene's
/// distance from the world origin and the camera's from Embree's frame. Measured: the slab of
/// tests/unit/render/translation_test.cpp renders the same mean at 8e10 extents and black at 8e11.
inline constexpr double kMaxExtentsAway = 1e10;

/// What a reach limit is for (docs/render.md §1, "Where Embree's floats are", the table): each
/// Embree test multiplies lengths up to a degree, and float's 3.4e38 bounds the products.
enum class Traced {
  curves,     ///< round linear curves: a discriminant of degree 6
  triangles,  ///< meshes, rectangles and boxes (all triangles in Embree): degree 3
  spheres,    ///< degree 2
  camera,     ///< the camera's lens: its rays start in double precision (kMaxExtentsAway)
};

/// The largest |coordinate − frame|∞ of each kind of shape (after scale and translate, radii
/// included). With every length at most the cube's diagonal 2√3·reach, each test's terms stay
/// below float's 3.4e38 by a margin of 10: curves 32·L⁶ (measured: change at 1e7, vanish at
/// 1e8), triangles L³ (same mean to 1e12, abort at 1e13), spheres L² (hold to 1e17; Embree
/// asserts ray origins within 1.8e19).
inline constexpr double kMaxReachCurves = 1e5;
inline constexpr double kMaxReachTriangles = 1e11;
inline constexpr double kMaxReachSpheres = 1e15;

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
  /// The scene is one convex shape (a box or a sphere): a ray that has just left it through its
  /// surface, going outward, hits nothing more.
  [[nodiscard]] bool lone_convex() const { return lone_convex_; }
  /// The scene is up to kMaxAnalyticShapes boxes, spheres and rectangles: intersected in closed
  /// form, in double precision, without Embree (docs/render.md §1, "Queries a path skips").
  [[nodiscard]] bool analytic() const { return analytic_; }
  static constexpr std::size_t kMaxAnalyticShapes = 8;

  [[nodiscard]] const std::vector<ShapeInfo>& shapes() const { return shapes_; }
  /// Uniform point on a shape's surface (pdf 1/area).
  [[nodiscard]] AreaSample sample_area(int shape, Pcg32& rng) const;
  /// Size of the scene's bounding box.
  [[nodiscard]] double extent() const { return extent_; }
  /// The world point that is Embree's origin (docs/render.md §1, "Where Embree's floats are").
  [[nodiscard]] const Vec3& frame() const { return frame_; }
  /// The largest |coordinate − frame()| of a box, for require_traceable.
  [[nodiscard]] double reach(const Vec3& lo, const Vec3& hi) const;
  /// The one table of what weft traces (docs/render.md §1): the largest reach of each kind; the
  /// camera's is kMaxExtentsAway of the smallest shape.
  [[nodiscard]] double max_reach(Traced kind) const;
  /// The one check of it: throws weft::Error "<what> <reach> from …" (what: "coordinates reach",
  /// "camera.position reaches") when `reach` (the largest |coordinate − frame()|) is beyond it.
  void require_traceable(double reach, Traced kind, const std::string& what) const;
  /// How far a ray leaving shape `shape` at `p` starts off it (along the normal): kSpawnOffset of
  /// that shape's extent plus p's coordinates in Embree's frame, where its floats round the hit
  /// (pbrt-v4 likewise bounds a hit's error by its own primitive's coordinates). Another shape's
  /// size does not enter: a large ground leaves the offsets on a small medium as they were.
  [[nodiscard]] double spawn_offset(const Vec3& p, int shape) const;

 private:
  /// intersect() over the shapes of an analytic() scene, each in closed form.
  [[nodiscard]] std::optional<SurfaceHit> intersect_analytic(const Vec3& o, const Vec3& d, double tmin,
                                                             double tmax) const;
  /// occluded() for an analytic() scene: any shape crossed in (tmin, tmax).
  [[nodiscard]] bool occluded_analytic(const Vec3& o, const Vec3& d, double tmin, double tmax) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<ShapeInfo> shapes_;
  double extent_ = 1.0;
  double min_extent_ = 1.0;  ///< of the smallest shape (kMaxExtentsAway)
  bool has_curves_ = false;
  double cube_ = kMaxReachCurves;  ///< rays starting beyond this reach are started where they enter it
  Vec3 frame_{0, 0, 0};
  bool lone_convex_ = false;
  bool analytic_ = false;
};

}  // namespace weft::render
