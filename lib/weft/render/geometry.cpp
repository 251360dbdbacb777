#include "weft/render/geometry.h"

#include <memory>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <embree3/rtcore.h>

#include "weft/core/error.h"
#include "weft/core/fp_hold.h"
#include "weft/curves/curve_io.h"

namespace weft::render {

struct Geometry::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }
};

namespace {

int lookup(const std::map<std::string, int>& table, const std::string& name) {
  if (name.empty()) return -1;
  return table.at(name);
}

void add_triangles(RTCDevice device, RTCScene scene, const TriangleMesh& mesh, const Vec3& frame, unsigned id) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3 x = mesh.vertices[i] - frame;
    for (int k = 0; k < 3; ++k) v[3 * i + static_cast<std::size_t>(k)] = static_cast<float>(x[k]);
  }
  auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                           3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) t[3 * i + k] = mesh.triangles[i][k];
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
}

void add_sphere(RTCDevice device, RTCScene scene, const Vec3& center, double r, const Vec3& frame, unsigned id) {
  const Vec3 c = center - frame;
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
  v[0] = static_cast<float>(c.x());
  v[1] = static_cast<float>(c.y());
  v[2] = static_cast<float>(c.z());
  v[3] = static_cast<float>(r);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
}

/// A curves shape read and transformed, in world coordinates, before it enters Embree.
struct CurveBuffers {
  std::vector<Vec3> points;  // every polyline's points (closed ones repeat the first)
  double radius = 0.0;
  std::vector<unsigned> first;       // index of each segment's first point
  std::vector<unsigned char> flags;  // which neighbours a segment joins (RTCCurveFlags)
};

/// Reads a curves shape: its points scaled and translated, the segments and their joints. The
/// bounds grow by every point ± radius.
CurveBuffers read_curve_buffers(const ShapeDesc& d, Vec3& lo, Vec3& hi) {
  const std::vector<curves::Curve> polylines = curves::read_curves(d.file);
  if (polylines.empty()) fail("curve file '{}' holds no curves", d.file);
  CurveBuffers b;
  b.radius = d.radius * d.scale;
  for (const auto& c : polylines) {
    if (c.points.size() < 2) continue;
    const auto base = static_cast<unsigned>(b.points.size());
    std::vector<curves::Point3> pts = c.points;
    if (c.closed) pts.push_back(c.points.front());
    for (const auto& q : pts) {
      const Vec3 x = Vec3(q[0], q[1], q[2]) * d.scale + d.translate;
      b.points.push_back(x);
      lo = lo.cwiseMin(x - Vec3::Constant(b.radius));
      hi = hi.cwiseMax(x + Vec3::Constant(b.radius));
    }
    const std::size_t segments = pts.size() - 1;
    for (std::size_t k = 0; k < segments; ++k) {
      b.first.push_back(base + static_cast<unsigned>(k));
      unsigned char f = 0;
      if (k > 0) f |= RTC_CURVE_FLAG_NEIGHBOR_LEFT;
      if (k + 1 < segments) f |= RTC_CURVE_FLAG_NEIGHBOR_RIGHT;
      b.flags.push_back(f);
    }
  }
  if (b.first.empty()) fail("curve file '{}' has no curve with two or more points", d.file);
  return b;
}

/// Fibres as Embree round linear curves: a cone per polyline segment with spheres at the joints,
/// i.e. exactly the swept tube of the generator's polylines (the geometry the voxelizer measured),
/// where a B-spline or Catmull–Rom basis would smooth it away from the points. Points enter
/// relative to `frame` (docs/render.md §1, "Where Embree's floats are").
void add_curves(RTCDevice device, RTCScene scene, const CurveBuffers& b, const Vec3& frame, unsigned id) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), b.points.size()));
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    const Vec3 x = b.points[i] - frame;
    for (int k = 0; k < 3; ++k) v[4 * i + static_cast<std::size_t>(k)] = static_cast<float>(x[k]);
    v[4 * i + 3] = static_cast<float>(b.radius);
  }
  auto* idx = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), b.first.size()));
  std::copy(b.first.begin(), b.first.end(), idx);
  auto* fl = static_cast<unsigned char*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR, sizeof(unsigned char), b.flags.size()));
  std::copy(b.flags.begin(), b.flags.end(), fl);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
}

/// A ray for Embree, in its frame (docs/render.md §1, "Where Embree's floats are"), or none when
/// it cannot meet any shape. Every shape lies within `cube` of the frame (Geometry::cube_); a ray
/// that starts farther out (a far camera, a collision deep in an unbounded medium) is started
/// where it enters that cube, `lead` along it, so Embree never meets an origin beyond what its
/// float tests can trace. Ordinary rays start where they are (lead 0).
std::optional<RTCRay> embree_ray(const Vec3& o_world, const Vec3& d, double tmin, double tmax, const Vec3& frame,
                                 double cube, double& lead) {
  Vec3 o = o_world - frame;
  lead = 0.0;
  if (o.cwiseAbs().maxCoeff() > cube) {
    double t_near = 0.0;
    double t_far = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      if (d[k] == 0.0) {
        if (std::abs(o[k]) > cube) return std::nullopt;
        continue;
      }
      const double t0 = (-cube - o[k]) / d[k];
      const double t1 = (cube - o[k]) / d[k];
      t_near = std::max(t_near, std::min(t0, t1));
      t_far = std::min(t_far, std::max(t0, t1));
    }
    if (!(t_near <= t_far) || t_far < tmin || t_near >= tmax) return std::nullopt;
    lead = t_near;
    o += lead * d;
    tmin = std::max(0.0, tmin - lead);
    tmax -= lead;
  }
  RTCRay ray{};
  ray.org_x = static_cast<float>(o.x());
  ray.org_y = static_cast<float>(o.y());
  ray.org_z = static_cast<float>(o.z());
  ray.dir_x = static_cast<float>(d.x());
  ray.dir_y = static_cast<float>(d.y());
  ray.dir_z = static_cast<float>(d.z());
  ray.tnear = static_cast<float>(tmin);
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  ray.tfar = tmax < kFloatMax ? static_cast<float>(tmax) : std::numeric_limits<float>::infinity();
  ray.mask = 0xFFFFFFFFU;
  ray.flags = 0;
  ray.time = 0.0f;
  return ray;
}

/// The origin of Embree's frame: the world's own when the shapes' box is centred within one
/// extent of it (its coordinates are then already of the order of the extent), else the box's
/// centre, so that a scene far from the world origin enters Embree's floats as it would at the
/// origin (docs/render.md §1, "Where Embree's floats are"). Ordinary scenes keep the world frame,
/// hence their bytes.
Vec3 frame_for(const Vec3& lo, const Vec3& hi) {
  const Vec3 centre = 0.5 * lo + 0.5 * hi;  // halves first: lo + hi may overflow
  const double extent = (hi - lo).maxCoeff();
  return centre.cwiseAbs().maxCoeff() <= extent ? Vec3::Zero() : centre;
}

}  // namespace

double Geometry::max_reach(Traced kind) const {
  // Rays start anywhere in the shapes' cube (embree_ray), and the curves' test takes the distance
  // from the origin among its lengths: beside curves, every shape keeps the curves' reach.
  const double beside = has_curves_ ? kMaxReachCurves : kMaxReachSpheres;
  switch (kind) {
    case Traced::curves:
      return kMaxReachCurves;
    case Traced::triangles:
      return std::min(kMaxReachTriangles, beside);
    case Traced::spheres:
      return std::min(kMaxReachSpheres, beside);
    case Traced::camera:
      // A far camera's rays are started where they enter the shapes' cube (embree_ray), in
      // double: exact while its double spacing stays below the smallest ray offset.
      return kMaxExtentsAway * min_extent_;
  }
  return 0.0;
}

void Geometry::require_traceable(double reach, Traced kind, const std::string& what) const {
  const double limit = max_reach(kind);
  if (reach <= limit) return;
  const char* name = kind == Traced::curves      ? "curves"
                     : kind == Traced::triangles ? "triangles"
                     : kind == Traced::spheres   ? "spheres"
                                                 : "the camera (1e10 extents of the smallest shape)";
  fail(
      "{} {:.3g} from the ray tracer's origin ({:.6g}, {:.6g}, {:.6g}), beyond the {:.3g} that single-precision "
      "Embree can trace for {} (docs/render.md §1, \"Where Embree's floats are\")",
      what, reach, frame_.x(), frame_.y(), frame_.z(), limit, name);
}

Geometry::Geometry(const SceneDesc& scene, const std::map<std::string, int>& material_index,
                   const std::map<std::string, int>& medium_index)
    : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice("threads=0");
  if (impl_->device == nullptr)
    fail("Embree: cannot create a device (error {})", static_cast<int>(rtcGetDeviceError(nullptr)));
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  // First every shape in world coordinates (files read, bounds known), then Embree's frame from
  // all the bounds, then each shape checked and added to Embree in that frame.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  std::vector<CurveBuffers> curve_buffers(scene.shapes.size());
  const auto in_shape = [&](std::size_t i, const auto& body) {
    try {
      body();
    } catch (const Error& e) {
      // The files a shape names are read here, once per render: name the shape (scene keys).
      fail("{}: shapes[{}]: {}", scene.source, i, e.what());
    }
  };
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    const ShapeDesc& d = scene.shapes[i];
    ShapeInfo s;
    in_shape(i, [&] {
      s.kind = d.kind;
      s.material = lookup(material_index, d.material);
      s.null_material = s.material >= 0 && scene.materials.at(d.material).kind == MaterialKind::null;
      s.interior = lookup(medium_index, d.interior);
      s.exterior = lookup(medium_index, d.exterior);
      s.emission = d.emission;
      s.lo = Vec3::Constant(std::numeric_limits<double>::infinity());
      s.hi = -s.lo;
      switch (d.kind) {
        case ShapeKind::sphere:
          s.center = d.center;
          s.radius = d.radius;
          s.area = 4.0 * std::numbers::pi * d.radius * d.radius;
          s.lo = d.center - Vec3::Constant(d.radius);
          s.hi = d.center + Vec3::Constant(d.radius);
          break;
        case ShapeKind::box:
        case ShapeKind::rectangle:
        case ShapeKind::mesh: {
          if (d.kind == ShapeKind::box) {
            s.mesh = box_mesh(d.min, d.max);
          } else if (d.kind == ShapeKind::rectangle) {
            s.mesh = rectangle_mesh(d.corner, d.edge_u, d.edge_v);
            s.corner = d.corner;
            s.u = d.edge_u;
            s.v = d.edge_v;
            s.gram_uu = d.edge_u.dot(d.edge_u);
            s.gram_uv = d.edge_u.dot(d.edge_v);
            s.gram_vv = d.edge_v.dot(d.edge_v);
          } else {
            s.mesh = load_mesh(d.file);
            for (auto& v : s.mesh.vertices) v = v * d.scale + d.translate;
          }
          double total = 0.0;
          for (const auto& tri : s.mesh.triangles) {
            const Vec3& a = s.mesh.vertices[tri[0]];
            const Vec3 cross = (s.mesh.vertices[tri[1]] - a).cross(s.mesh.vertices[tri[2]] - a);
            total += 0.5 * cross.norm();
            s.area_cdf.push_back(total);
            s.normals.push_back(cross.normalized());
          }
          for (auto& c : s.area_cdf) c /= total;
          s.area = total;
          for (const auto& v : s.mesh.vertices) {
            s.lo = s.lo.cwiseMin(v);
            s.hi = s.hi.cwiseMax(v);
          }
          break;
        }
        case ShapeKind::curves:
          curve_buffers[i] = read_curve_buffers(d, s.lo, s.hi);
          s.curve_segments = curve_buffers[i].first.size();
          break;
      }
    });
    lo = lo.cwiseMin(s.lo);
    hi = hi.cwiseMax(s.hi);
    s.extent = std::max(1e-6, (s.hi - s.lo).maxCoeff());
    shapes_.push_back(std::move(s));
  }
  if (shapes_.empty()) return;
  frame_ = frame_for(lo, hi);
  extent_ = std::max(1e-6, (hi - lo).maxCoeff());
  min_extent_ = extent_;
  for (const ShapeInfo& s : shapes_) {
    min_extent_ = std::min(min_extent_, s.extent);
    has_curves_ = has_curves_ || s.kind == ShapeKind::curves;
  }
  // World coordinates are doubles: their spacing at the frame, 2^-52·|frame|, must stay below the
  // smallest ray offset (kSpawnOffset·the smallest shape's extent), else rays start inside the
  // surface they leave (docs/render.md §1, "Where Embree's floats are").
  const double away = frame_.cwiseAbs().maxCoeff();
  if (away > kMaxExtentsAway * min_extent_)
    fail(
        "{}: shapes: the scene's smallest shape (extent {:.3g}) lies {:.3g} from the world origin, {:.2g} times its "
        "extent; beyond {:.0e} times, double precision is coarser than the ray offsets (docs/render.md §1, \"Where "
        "Embree's floats are\"): move it nearer the origin",
        scene.source, min_extent_, away, away / min_extent_, kMaxExtentsAway);
  for (std::size_t i = 0; i < shapes_.size(); ++i) {
    const ShapeInfo& s = shapes_[i];
    // Rays from beyond every shape and beyond where every Embree test takes an origin as it is
    // (the curves' reach) are started where they enter this cube.
    cube_ = std::max(cube_, reach(s.lo, s.hi));
    in_shape(i, [&] {
      // The one rule of what Embree can trace, by the test each kind meets, after scale and translate.
      const Traced kind = s.kind == ShapeKind::sphere   ? Traced::spheres
                          : s.kind == ShapeKind::curves ? Traced::curves
                                                        : Traced::triangles;
      require_traceable(reach(s.lo, s.hi), kind, "coordinates reach");
      const auto id = static_cast<unsigned>(i);
      switch (s.kind) {
        case ShapeKind::sphere:
          add_sphere(impl_->device, impl_->scene, s.center, s.radius, frame_, id);
          break;
        case ShapeKind::curves:
          add_curves(impl_->device, impl_->scene, curve_buffers[i], frame_, id);
          break;
        default:
          add_triangles(impl_->device, impl_->scene, s.mesh, frame_, id);
          break;
      }
    });
  }
  {
    const HeldFpExceptions hold;  // Embree's builder computes with ±inf bounds on purpose
    rtcCommitScene(impl_->scene);
  }
  lone_convex_ = shapes_.size() == 1 && (shapes_[0].kind == ShapeKind::box || shapes_[0].kind == ShapeKind::sphere);
  analytic_ = shapes_.size() <= kMaxAnalyticShapes && std::all_of(shapes_.begin(), shapes_.end(), [](const auto& s) {
                return s.kind == ShapeKind::box || s.kind == ShapeKind::sphere || s.kind == ShapeKind::rectangle;
              });
  if (rtcGetDeviceError(impl_->device) != RTC_ERROR_NONE) fail("Embree: scene build failed");
}

double Geometry::reach(const Vec3& lo, const Vec3& hi) const {
  return std::max((lo - frame_).cwiseAbs().maxCoeff(), (hi - frame_).cwiseAbs().maxCoeff());
}

double Geometry::spawn_offset(const Vec3& p, int shape) const {
  return kSpawnOffset * (shapes_[static_cast<std::size_t>(shape)].extent + (p - frame_).cwiseAbs().maxCoeff());
}

Geometry::~Geometry() = default;

std::optional<SurfaceHit> Geometry::intersect(const Vec3& o, const Vec3& d, double tmin, double tmax) const {
  if (shapes_.empty()) return std::nullopt;
  if (analytic_) return intersect_analytic(o, d, tmin, tmax);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  double lead = 0.0;
  const std::optional<RTCRay> ray = embree_ray(o, d, tmin, tmax, frame_, cube_, lead);
  if (!ray) return std::nullopt;
  RTCRayHit rh{};
  rh.ray = *ray;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  {
    const HeldFpExceptions hold;  // traversal uses 1/d of zero direction components (= ±inf)
    rtcIntersect1(impl_->scene, &context, &rh);
  }
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  SurfaceHit hit;
  hit.t = lead + rh.ray.tfar;
  hit.shape = static_cast<int>(rh.hit.geomID);
  hit.p = o + hit.t * d;
  const ShapeInfo& s = shapes_[static_cast<std::size_t>(hit.shape)];
  if (s.kind == ShapeKind::sphere) {
    hit.n = (hit.p - s.center).normalized();
    // Snap the point onto the sphere: float hit distances drift by ~1e-7 of the scene size.
    hit.p = s.center + s.radius * hit.n;
  } else if (s.kind == ShapeKind::curves) {
    // Embree's geometric normal of the round curve's surface at the hit (not normalised).
    hit.n = Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
  } else {
    hit.n = s.normals[rh.hit.primID];  // as computed per hit before, once per triangle
  }
  return hit;
}

namespace {

/// Where a ray crosses a shape of an analytic scene: its distance and, for a box, the face (axis
/// and whether the ray enters by it). The hit point and normal are made once, for the nearest.
struct Crossing {
  double t = 0.0;
  int axis = -1;
  bool entering = false;
};

/// The sphere's nearer crossing in (tmin, tmax), or its farther one (a ray from inside).
[[gnu::always_inline]] inline std::optional<Crossing> cross_sphere(const ShapeInfo& s, const Vec3& o, const Vec3& d,
                                                                   double tmin, double tmax) {
  const Vec3 oc = o - s.center;
  const double a = d.squaredNorm();
  const double b = oc.dot(d);
  const double disc = b * b - a * (oc.squaredNorm() - s.radius * s.radius);
  if (!(disc >= 0.0) || !(a > 0.0)) return std::nullopt;
  const double root = std::sqrt(disc);
  const double near = (-b - root) / a;
  const double t = near > tmin ? near : (-b + root) / a;
  if (!(t > tmin && t < tmax)) return std::nullopt;
  return Crossing{t};
}

/// The box's slabs: the face the ray enters by in (tmin, tmax), or the one it leaves by.
[[gnu::always_inline]] inline std::optional<Crossing> cross_box(const ShapeInfo& s, const Vec3& o, const Vec3& d,
                                                                double tmin, double tmax) {
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  int axis_near = -1;
  int axis_far = -1;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (o[k] < s.lo[k] || o[k] > s.hi[k]) return std::nullopt;
      continue;
    }
    const double a = (s.lo[k] - o[k]) / d[k];
    const double b = (s.hi[k] - o[k]) / d[k];
    const double lo = std::min(a, b);
    const double hi = std::max(a, b);
    if (lo > t_near) {
      t_near = lo;
      axis_near = k;
    }
    if (hi < t_far) {
      t_far = hi;
      axis_far = k;
    }
  }
  if (t_near > t_far) return std::nullopt;
  const bool entering = t_near > tmin;
  const double t = entering ? t_near : t_far;
  const int axis = entering ? axis_near : axis_far;
  if (axis < 0 || !(t > tmin && t < tmax)) return std::nullopt;
  return Crossing{t, axis, entering};
}

/// The rectangle's plane crossing in (tmin, tmax) when it falls inside corner + [0, 1]·u +
/// [0, 1]·v.
[[gnu::always_inline]] inline std::optional<Crossing> cross_rectangle(const ShapeInfo& s, const Vec3& o, const Vec3& d,
                                                                      double tmin, double tmax) {
  const Vec3& n = s.normals.front();
  const double across = n.dot(d);
  if (across == 0.0) return std::nullopt;  // parallel to the plane (or in it: no area is crossed)
  const double t = n.dot(s.corner - o) / across;
  if (!(t > tmin && t < tmax)) return std::nullopt;
  const Vec3 w = o + t * d - s.corner;
  const double wu = w.dot(s.u);
  const double wv = w.dot(s.v);
  const double det = s.gram_uu * s.gram_vv - s.gram_uv * s.gram_uv;
  const double a = (s.gram_vv * wu - s.gram_uv * wv) / det;
  const double b = (s.gram_uu * wv - s.gram_uv * wu) / det;
  if (!(a >= 0.0 && a <= 1.0 && b >= 0.0 && b <= 1.0)) return std::nullopt;
  return Crossing{t};
}

// Inlined, with every shape's test, into both loops (intersect_analytic, occluded_analytic):
// called, or with only the box's test inlined, the front-lit cloth's samples cost 1–3 % more.
[[gnu::always_inline]] inline std::optional<Crossing> cross(const ShapeInfo& s, const Vec3& o, const Vec3& d,
                                                            double tmin, double tmax) {
  switch (s.kind) {
    case ShapeKind::box:
      return cross_box(s, o, d, tmin, tmax);
    case ShapeKind::sphere:
      return cross_sphere(s, o, d, tmin, tmax);
    default:
      return cross_rectangle(s, o, d, tmin, tmax);
  }
}

}  // namespace

std::optional<SurfaceHit> Geometry::intersect_analytic(const Vec3& o, const Vec3& d, double tmin, double tmax) const {
  // docs/render.md §1, "Queries a path skips": a few boxes, spheres and rectangles, each in
  // closed form and in double precision (Embree's answer is the same surfaces in float); the
  // nearest crossing, each shape's test bounded by the nearest found so far.
  std::size_t best = shapes_.size();
  Crossing nearest;
  double bound = tmax;
  for (std::size_t i = 0; i < shapes_.size(); ++i) {
    if (const std::optional<Crossing> c = cross(shapes_[i], o, d, tmin, bound)) {
      best = i;
      nearest = *c;
      bound = c->t;
    }
  }
  if (best == shapes_.size()) return std::nullopt;
  const ShapeInfo& s = shapes_[best];
  SurfaceHit hit;
  hit.t = nearest.t;
  hit.shape = static_cast<int>(best);
  hit.p = o + hit.t * d;
  if (s.kind == ShapeKind::sphere) {
    hit.n = (hit.p - s.center).normalized();
    hit.p = s.center + s.radius * hit.n;  // as the Embree path snaps it
  } else if (s.kind == ShapeKind::box) {
    // Entering through the near face, the ray goes against its outward normal; leaving, along it
    // (the outward normal, as the box mesh's winding gives it).
    Vec3 n = Vec3::Zero();
    n[nearest.axis] = (d[nearest.axis] > 0.0) == nearest.entering ? -1.0 : 1.0;
    hit.n = n;
  } else {
    hit.n = s.normals.front();  // its triangles' normal (by winding, u × v), from either side
  }
  return hit;
}

bool Geometry::occluded_analytic(const Vec3& o, const Vec3& d, double tmin, double tmax) const {
  for (const ShapeInfo& s : shapes_)
    if (cross(s, o, d, tmin, tmax)) return true;
  return false;
}

double Geometry::clearance(const Vec3& p, const Vec3& d) const {
  // Going over every shape is only cheaper than the BVH query it saves for a few shapes.
  constexpr std::size_t kMaxShapes = 8;
  if (shapes_.empty() || shapes_.size() > kMaxShapes) return 0.0;
  // Embree works in float: vertices, ray origin and direction are rounded to 6e-8 of the
  // coordinates in its frame and its hit distances are exact to a few such units (divided by the
  // direction component across the face hit). Every surface of a shape is moved towards p by the
  // larger of the shape's ray offsets at p and at its farthest corner (1e-5 of the shape's extent
  // plus the coordinates of the ray's origin or of the shape's vertices, the larger of which
  // bounds those units), so the bound stays below Embree's distance at any angle.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double bound = kInf;
  for (std::size_t i = 0; i < shapes_.size(); ++i) {
    const ShapeInfo& s = shapes_[i];
    const int id = static_cast<int>(i);
    const double delta = std::max({spawn_offset(p, id), spawn_offset(s.lo, id), spawn_offset(s.hi, id)});
    if (s.kind == ShapeKind::sphere) {
      bound = std::min(bound, std::max(0.0, std::abs((p - s.center).norm() - s.radius) - delta));
      continue;
    }
    const bool inside_shrunk = (p.array() > s.lo.array() + delta).all() && (p.array() < s.hi.array() - delta).all();
    if (inside_shrunk && s.kind == ShapeKind::box) {
      // Inside a box, the first surface is where the ray leaves it (of the box shrunk by delta).
      for (int k = 0; k < 3; ++k) {
        if (d[k] > 0.0) bound = std::min(bound, (s.hi[k] - delta - p[k]) / d[k]);
        if (d[k] < 0.0) bound = std::min(bound, (s.lo[k] + delta - p[k]) / d[k]);
      }
      continue;
    }
    // Otherwise any surface of the shape lies in its bounds (grown by delta): the ray's entry
    // into them, if p is outside; nothing is known from inside them.
    double t_near = 0.0;
    double t_far = kInf;
    for (int k = 0; k < 3; ++k) {
      const double lo = s.lo[k] - delta;
      const double hi = s.hi[k] + delta;
      if (d[k] == 0.0) {
        if (p[k] < lo || p[k] > hi) t_far = -1.0;  // parallel to the slab and outside it: a miss
        continue;
      }
      const double a = (lo - p[k]) / d[k];
      const double b = (hi - p[k]) / d[k];
      t_near = std::max(t_near, std::min(a, b));
      t_far = std::min(t_far, std::max(a, b));
    }
    if (t_near > t_far) continue;   // the ray misses the bounds (or they lie behind it)
    if (t_near <= 0.0) return 0.0;  // p inside the bounds of a mesh or curves
    bound = std::min(bound, t_near);
  }
  return bound;
}

bool Geometry::occluded(const Vec3& o, const Vec3& d, double tmin, double tmax) const {
  if (shapes_.empty()) return false;
  if (analytic_) return occluded_analytic(o, d, tmin, tmax);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  double lead = 0.0;
  std::optional<RTCRay> ray = embree_ray(o, d, tmin, tmax, frame_, cube_, lead);
  if (!ray) return false;
  {
    const HeldFpExceptions hold;  // as in intersect()
    rtcOccluded1(impl_->scene, &context, &*ray);
  }
  return ray->tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

AreaSample Geometry::sample_area(int shape, Pcg32& rng) const {
  const ShapeInfo& s = shapes_[static_cast<std::size_t>(shape)];
  if (s.kind == ShapeKind::sphere) {
    const double z = 1.0 - 2.0 * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * std::numbers::pi * rng.uniform();
    const Vec3 n(r * std::cos(phi), r * std::sin(phi), z);
    return {s.center + s.radius * n, n};
  }
  const double u = rng.uniform();
  const auto it = std::upper_bound(s.area_cdf.begin(), s.area_cdf.end(), u);
  const std::size_t index =
      std::min<std::size_t>(static_cast<std::size_t>(it - s.area_cdf.begin()), s.area_cdf.size() - 1);
  const auto& tri = s.mesh.triangles[index];
  const Vec3& a = s.mesh.vertices[tri[0]];
  const Vec3& b = s.mesh.vertices[tri[1]];
  const Vec3& c = s.mesh.vertices[tri[2]];
  const double su = std::sqrt(rng.uniform());
  const double b1 = 1.0 - su;
  const double b2 = rng.uniform() * su;
  return {a + b1 * (b - a) + b2 * (c - a), s.normals[index]};
}

}  // namespace weft::render
