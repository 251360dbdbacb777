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

void add_triangles(RTCDevice device, RTCScene scene, const TriangleMesh& mesh, unsigned id) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = static_cast<float>(mesh.vertices[i][k]);
  auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                           3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) t[3 * i + k] = mesh.triangles[i][k];
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
}

void add_sphere(RTCDevice device, RTCScene scene, const Vec3& c, double r, unsigned id) {
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

/// Fibres as Embree round linear curves: a cone per polyline segment with spheres at the joints,
/// i.e. exactly the swept tube of the generator's polylines (the geometry the voxelizer measured),
/// where a B-spline or Catmull–Rom basis would smooth it away from the points. Returns the
/// number of segments; the bounds grow by every point ± radius.
std::size_t add_curves(RTCDevice device, RTCScene scene, const ShapeDesc& d, unsigned id, Vec3& lo, Vec3& hi) {
  const std::vector<curves::Curve> polylines = curves::read_curves(d.file);
  if (polylines.empty()) fail("curve file '{}' holds no curves", d.file);
  const double radius = d.radius * d.scale;
  std::vector<float> vertices;
  std::vector<unsigned> first;       // index of each segment's first vertex
  std::vector<unsigned char> flags;  // which neighbours a segment joins (RTCCurveFlags)
  for (const auto& c : polylines) {
    if (c.points.size() < 2) continue;
    const auto base = static_cast<unsigned>(vertices.size() / 4);
    std::vector<curves::Point3> pts = c.points;
    if (c.closed) pts.push_back(c.points.front());
    for (const auto& q : pts) {
      const Vec3 x = Vec3(q[0], q[1], q[2]) * d.scale + d.translate;
      vertices.insert(vertices.end(), {static_cast<float>(x.x()), static_cast<float>(x.y()), static_cast<float>(x.z()),
                                       static_cast<float>(radius)});
      lo = lo.cwiseMin(x - Vec3::Constant(radius));
      hi = hi.cwiseMax(x + Vec3::Constant(radius));
    }
    const std::size_t segments = pts.size() - 1;
    for (std::size_t k = 0; k < segments; ++k) {
      first.push_back(base + static_cast<unsigned>(k));
      unsigned char f = 0;
      if (k > 0) f |= RTC_CURVE_FLAG_NEIGHBOR_LEFT;
      if (k + 1 < segments) f |= RTC_CURVE_FLAG_NEIGHBOR_RIGHT;
      flags.push_back(f);
    }
  }
  if (first.empty()) fail("curve file '{}' has no curve with two or more points", d.file);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                        4 * sizeof(float), vertices.size() / 4));
  std::copy(vertices.begin(), vertices.end(), v);
  auto* idx = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), first.size()));
  std::copy(first.begin(), first.end(), idx);
  auto* fl = static_cast<unsigned char*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR, sizeof(unsigned char), flags.size()));
  std::copy(flags.begin(), flags.end(), fl);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
  return first.size();
}

RTCRay make_ray(const Vec3& o, const Vec3& d, double tmin, double tmax) {
  RTCRay ray{};
  ray.org_x = static_cast<float>(o.x());
  ray.org_y = static_cast<float>(o.y());
  ray.org_z = static_cast<float>(o.z());
  ray.dir_x = static_cast<float>(d.x());
  ray.dir_y = static_cast<float>(d.y());
  ray.dir_z = static_cast<float>(d.z());
  ray.tnear = static_cast<float>(tmin);
  ray.tfar = std::isfinite(tmax) ? static_cast<float>(tmax) : std::numeric_limits<float>::infinity();
  ray.mask = 0xFFFFFFFFU;
  ray.flags = 0;
  ray.time = 0.0f;
  return ray;
}

}  // namespace

Geometry::Geometry(const SceneDesc& scene, const std::map<std::string, int>& material_index,
                   const std::map<std::string, int>& medium_index)
    : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice("threads=0");
  if (impl_->device == nullptr)
    fail("Embree: cannot create a device (error {})", static_cast<int>(rtcGetDeviceError(nullptr)));
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    const ShapeDesc& d = scene.shapes[i];
    ShapeInfo s;
    try {
      s.kind = d.kind;
      s.material = lookup(material_index, d.material);
      s.null_material = s.material >= 0 && scene.materials.at(d.material).kind == MaterialKind::null;
      s.interior = lookup(medium_index, d.interior);
      s.exterior = lookup(medium_index, d.exterior);
      s.emission = d.emission;
      const auto id = static_cast<unsigned>(i);
      const Vec3 lo_before = lo;
      const Vec3 hi_before = hi;
      lo = Vec3::Constant(std::numeric_limits<double>::infinity());
      hi = -lo;
      switch (d.kind) {
        case ShapeKind::sphere:
          s.center = d.center;
          s.radius = d.radius;
          s.area = 4.0 * std::numbers::pi * d.radius * d.radius;
          add_sphere(impl_->device, impl_->scene, d.center, d.radius, id);
          lo = lo.cwiseMin(d.center - Vec3::Constant(d.radius));
          hi = hi.cwiseMax(d.center + Vec3::Constant(d.radius));
          break;
        case ShapeKind::box:
        case ShapeKind::rectangle:
        case ShapeKind::mesh: {
          if (d.kind == ShapeKind::box) {
            s.mesh = box_mesh(d.min, d.max);
          } else if (d.kind == ShapeKind::rectangle) {
            s.mesh = rectangle_mesh(d.corner, d.edge_u, d.edge_v);
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
            lo = lo.cwiseMin(v);
            hi = hi.cwiseMax(v);
          }
          add_triangles(impl_->device, impl_->scene, s.mesh, id);
          break;
        }
        case ShapeKind::curves:
          s.curve_segments = add_curves(impl_->device, impl_->scene, d, id, lo, hi);
          break;
      }
      // Embree stores coordinates as floats: a shape that leaves float's range once scaled and
      // translated (a mesh "scale" of 1e300) would be inf there and silently vanish from the
      // image, so it is an error like a non-finite coordinate in the file (docs/scene-format.md).
      const double reach = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
      if (!(reach <= std::numeric_limits<float>::max()))
        fail("coordinates reach {:.3g}, beyond the float range of the ray tracer ({:.3g})", reach,
             static_cast<double>(std::numeric_limits<float>::max()));
      s.lo = lo;
      s.hi = hi;
      lo = lo.cwiseMin(lo_before);
      hi = hi.cwiseMax(hi_before);
    } catch (const Error& e) {
      // The files a shape names are read here, once per render: name the shape (scene keys).
      fail("{}: shapes[{}]: {}", scene.source, i, e.what());
    }
    shapes_.push_back(std::move(s));
  }
  {
    const HeldFpExceptions hold;  // Embree's builder computes with ±inf bounds on purpose
    rtcCommitScene(impl_->scene);
  }
  if (!shapes_.empty()) extent_ = std::max(1e-6, (hi - lo).maxCoeff());
  lone_convex_ = shapes_.size() == 1 && (shapes_[0].kind == ShapeKind::box || shapes_[0].kind == ShapeKind::sphere);
  if (rtcGetDeviceError(impl_->device) != RTC_ERROR_NONE) fail("Embree: scene build failed");
}

Geometry::~Geometry() = default;

std::optional<SurfaceHit> Geometry::intersect(const Vec3& o, const Vec3& d, double tmin, double tmax) const {
  if (shapes_.empty()) return std::nullopt;
  if (lone_convex_) return intersect_lone(o, d, tmin, tmax);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray = make_ray(o, d, tmin, tmax);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  {
    const HeldFpExceptions hold;  // traversal uses 1/d of zero direction components (= ±inf)
    rtcIntersect1(impl_->scene, &context, &rh);
  }
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  SurfaceHit hit;
  hit.t = rh.ray.tfar;
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

std::optional<SurfaceHit> Geometry::intersect_lone(const Vec3& o, const Vec3& d, double tmin, double tmax) const {
  // docs/render.md §1, "Queries a path skips": one box or sphere, in closed form and in double
  // precision (Embree's answer is the same surface in float).
  const ShapeInfo& s = shapes_[0];
  SurfaceHit hit;
  hit.shape = 0;
  if (s.kind == ShapeKind::sphere) {
    const Vec3 oc = o - s.center;
    const double a = d.squaredNorm();
    const double b = oc.dot(d);
    const double disc = b * b - a * (oc.squaredNorm() - s.radius * s.radius);
    if (!(disc >= 0.0) || !(a > 0.0)) return std::nullopt;
    const double root = std::sqrt(disc);
    const double near = (-b - root) / a;
    const double far = (-b + root) / a;
    hit.t = near > tmin ? near : far;
    if (!(hit.t > tmin && hit.t < tmax)) return std::nullopt;
    hit.p = o + hit.t * d;
    hit.n = (hit.p - s.center).normalized();
    hit.p = s.center + s.radius * hit.n;  // as the Embree path snaps it
    return hit;
  }
  // A box: the slabs. near/far faces per axis; the normal is the outward one of the face hit.
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
  const bool front = t_near > tmin;
  hit.t = front ? t_near : t_far;
  const int k = front ? axis_near : axis_far;
  if (k < 0 || !(hit.t > tmin && hit.t < tmax)) return std::nullopt;
  hit.p = o + hit.t * d;
  // Entering through the near face, the ray goes against its outward normal; leaving, along it.
  Vec3 n = Vec3::Zero();
  n[k] = (d[k] > 0.0) == front ? -1.0 : 1.0;
  hit.n = n;
  return hit;
}

double Geometry::clearance(const Vec3& p, const Vec3& d) const {
  // Going over every shape is only cheaper than the BVH query it saves for a few shapes.
  constexpr std::size_t kMaxShapes = 8;
  if (shapes_.empty() || shapes_.size() > kMaxShapes) return 0.0;
  // Embree works in float: vertices, ray origin and direction are rounded to 6e-8 of the
  // coordinates and its hit distances are exact to a few such units (divided by the direction
  // component across the face hit). Every surface is moved by delta = 1e-5 of the coordinates
  // (the ray offsets' eps) towards p, so the bound stays below Embree's distance at any angle.
  const double delta = 1e-5 * (extent_ + p.cwiseAbs().maxCoeff());
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double bound = kInf;
  for (const ShapeInfo& s : shapes_) {
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
  if (lone_convex_) return intersect_lone(o, d, tmin, tmax).has_value();
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = make_ray(o, d, tmin, tmax);
  {
    const HeldFpExceptions hold;  // as in intersect()
    rtcOccluded1(impl_->scene, &context, &ray);
  }
  return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
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
