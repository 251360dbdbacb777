#include "weft/fibres/capsule_index.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "weft/core/error.h"

namespace weft::fibres {
namespace {

constexpr double kHuge = 1e300;
constexpr std::uint32_t kLeafSize = 4;

double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Point3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

/// Hull of `lo..hi` and the line's interval in the sphere of radius r at c (|d| = 1).
void sphere_hull(const Point3& o, const Point3& d, const Point3& c, double r, double& lo, double& hi) {
  const Point3 oc = sub(o, c);
  const double b = dot(oc, d);
  // b² − (|oc|² − r²) as |oc − b·d|-form: r² − |oc⊥|², free of the cancellation of b² − |oc|².
  const Point3 perp{oc[0] - b * d[0], oc[1] - b * d[1], oc[2] - b * d[2]};
  const double disc = r * r - dot(perp, perp);
  if (disc < 0.0) return;
  const double s = std::sqrt(disc);
  lo = std::min(lo, -b - s);
  hi = std::max(hi, -b + s);
}

}  // namespace

bool ray_capsule(const Point3& o, const Point3& d, const Point3& a, const Point3& b, double r, Interval& out) {
  double lo = kHuge;
  double hi = -kHuge;
  sphere_hull(o, d, a, r, lo, hi);
  const Point3 ba = sub(b, a);
  const double len2 = dot(ba, ba);
  if (len2 > 0.0) {
    sphere_hull(o, d, b, r, lo, hi);
    const double len = std::sqrt(len2);
    const Point3 u{ba[0] / len, ba[1] / len, ba[2] / len};
    const Point3 oa = sub(o, a);
    const double du = dot(d, u);
    const double ou = dot(oa, u);
    const Point3 dp{d[0] - du * u[0], d[1] - du * u[1], d[2] - du * u[2]};
    const Point3 op{oa[0] - ou * u[0], oa[1] - ou * u[1], oa[2] - ou * u[2]};
    const double qa = dot(dp, dp);
    const double qb = dot(op, dp);
    const double qc = dot(op, op) - r * r;
    // The infinite cylinder |op + t·dp| ≤ r.
    double c0 = 1.0;
    double c1 = 0.0;
    if (qa > 1e-24) {
      const double disc = qb * qb - qa * qc;
      if (disc >= 0.0) {
        const double s = std::sqrt(disc);
        c0 = (-qb - s) / qa;
        c1 = (-qb + s) / qa;
      }
    } else if (qc <= 0.0) {
      c0 = -kHuge;  // along the axis, inside the radius
      c1 = kHuge;
    }
    // The slab 0 ≤ ou + t·du ≤ len between the end caps.
    if (c0 <= c1) {
      if (std::abs(du) > 1e-12) {
        const double s0 = -ou / du;
        const double s1 = (len - ou) / du;
        c0 = std::max(c0, std::min(s0, s1));
        c1 = std::min(c1, std::max(s0, s1));
      } else if (ou < 0.0 || ou > len) {
        c1 = c0 - 1.0;  // across the axis, outside the slab: the spheres cover the rest
      }
      if (c0 <= c1) {
        lo = std::min(lo, c0);
        hi = std::max(hi, c1);
      }
    }
  }
  if (lo > hi) return false;
  out = {lo, hi};
  return true;
}

CapsuleIndex::CapsuleIndex(const FibreSet& fibres) {
  fibres.check("fibres");
  std::vector<Capsule> input;
  for (std::size_t f = 0; f < fibres.size(); ++f) {
    const double r = fibres.radius[f];
    const std::uint64_t b = fibres.offsets[f];
    const std::uint64_t e = fibres.offsets[f + 1];
    if (e - b == 1) input.push_back({fibres.points[b], fibres.points[b], r});
    for (std::uint64_t i = b + 1; i < e; ++i) input.push_back({fibres.points[i - 1], fibres.points[i], r});
  }
  if (input.size() >= std::numeric_limits<std::uint32_t>::max() / 2)
    fail("fibres: {} segments are too many for one index", input.size());
  std::vector<Point3> centre(input.size());
  for (std::size_t i = 0; i < input.size(); ++i) {
    for (int c = 0; c < 3; ++c) centre[i][c] = 0.5 * (input[i].a[c] + input[i].b[c]);
  }
  std::vector<std::uint32_t> order(input.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
  caps_.reserve(input.size());
  nodes_.reserve(2 * input.size() / kLeafSize + 2);
  if (!input.empty()) {
    build(order, 0, static_cast<std::uint32_t>(order.size()), centre, input);
    lo_ = nodes_[0].lo;
    hi_ = nodes_[0].hi;
  }
}

std::uint32_t CapsuleIndex::build(std::vector<std::uint32_t>& order, std::uint32_t begin, std::uint32_t end,
                                  const std::vector<Point3>& centre, const std::vector<Capsule>& input) {
  const auto self = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  Point3 lo{kHuge, kHuge, kHuge};
  Point3 hi{-kHuge, -kHuge, -kHuge};
  Point3 clo = lo;
  Point3 chi = hi;
  for (std::uint32_t i = begin; i < end; ++i) {
    const Capsule& c = input[order[i]];
    // A little padding: a ray grazing a capsule must not be culled by rounding of the box.
    const double pad = c.r * (1.0 + 1e-9) + 1e-12;
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], std::min(c.a[k], c.b[k]) - pad);
      hi[k] = std::max(hi[k], std::max(c.a[k], c.b[k]) + pad);
      clo[k] = std::min(clo[k], centre[order[i]][k]);
      chi[k] = std::max(chi[k], centre[order[i]][k]);
    }
  }
  if (end - begin <= kLeafSize) {
    nodes_[self] = {lo, hi, static_cast<std::uint32_t>(caps_.size()), end - begin};
    for (std::uint32_t i = begin; i < end; ++i) caps_.push_back(input[order[i]]);
    return self;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  }
  const std::uint32_t mid = begin + (end - begin) / 2;
  // Ties broken by index: the same fibres give the same tree on every machine.
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](std::uint32_t x, std::uint32_t y) {
                     return centre[x][axis] < centre[y][axis] || (centre[x][axis] == centre[y][axis] && x < y);
                   });
  build(order, begin, mid, centre, input);
  const std::uint32_t right = build(order, mid, end, centre, input);
  nodes_[self] = {lo, hi, right, 0};
  return self;
}

void CapsuleIndex::intersect(const Point3& o, const Point3& d, double tmin, double tmax,
                             std::vector<Interval>& out) const {
  if (nodes_.empty() || !(tmin <= tmax)) return;
  // Slab test with reciprocal directions; a component that is (nearly) 0 is a ray parallel to
  // those slabs: inside or outside them for every t.
  Point3 inv{};
  std::array<bool, 3> flat{};
  for (int k = 0; k < 3; ++k) {
    flat[k] = std::abs(d[k]) < 1e-15;
    inv[k] = flat[k] ? 0.0 : 1.0 / d[k];
  }
  const auto hits_box = [&](const Node& n) {
    double t0 = tmin;
    double t1 = tmax;
    for (int k = 0; k < 3; ++k) {
      if (flat[k]) {
        if (o[k] < n.lo[k] || o[k] > n.hi[k]) return false;
        continue;
      }
      double a = (n.lo[k] - o[k]) * inv[k];
      double b = (n.hi[k] - o[k]) * inv[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
      if (t0 > t1) return false;
    }
    return true;
  };
  std::array<std::uint32_t, 128> stack{};
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!hits_box(n)) continue;
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
        Interval iv{};
        if (!ray_capsule(o, d, caps_[i].a, caps_[i].b, caps_[i].r, iv)) continue;
        iv[0] = std::max(iv[0], tmin);
        iv[1] = std::min(iv[1], tmax);
        if (iv[0] <= iv[1]) out.push_back(iv);
      }
      continue;
    }
    const auto self = static_cast<std::uint32_t>(&n - nodes_.data());
    stack[top++] = n.first;
    stack[top++] = self + 1;
  }
}

}  // namespace weft::fibres
