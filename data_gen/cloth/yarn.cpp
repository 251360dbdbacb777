#include "data_gen/cloth/yarn.h"

#include <algorithm>
#include <cmath>
#include <numbers>

// CGAL is here for the minimum-distance fibre placement: a Delaunay triangulation answers
// "nearest placed fibre to this candidate" in O(log n) expected time with exact predicates, which
// keeps rejection sampling of a few thousand fibres per ply cheap and robust (no hand-rolled grid
// whose cell size would have to track the ellipse and the spacing).
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "weft/core/error.h"

namespace weft::cloth {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

Point3 add(const Point3& a, const Point3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Point3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Point3 scale(const Point3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Point3& a) { return std::sqrt(dot(a, a)); }
Point3 normalized(const Point3& a) {
  const double l = norm(a);
  return l > 0.0 ? scale(a, 1.0 / l) : Point3{0.0, 0.0, 0.0};
}
Point3 lerp(const Point3& a, const Point3& b, double t) { return add(a, scale(sub(b, a), t)); }

double normal_deviate(Pcg32& rng, double mean, double sd) {
  // Box–Muller; uniform_open keeps log away from 0.
  const double u1 = rng.uniform_open();
  const double u2 = rng.uniform();
  return mean + sd * std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
}

// Number of events for an expected count λ: floor(λ) plus one with probability frac(λ), so the
// mean is exact and a density of 0 gives none.
int event_count(double expected, Pcg32& rng) {
  const double whole = std::floor(expected);
  return static_cast<int>(whole) + (rng.uniform() < expected - whole ? 1 : 0);
}

}  // namespace

double fiber_density(double R, double epsilon, double beta) {
  if (R < 0.0 || R > 1.0) return 0.0;
  const double e = std::numbers::e;
  // (e − e^R)/(e − 1) ∈ [0, 1]; written with expm1 so R → 1 does not cancel.
  const double base = -std::expm1(R - 1.0) * e / (e - 1.0);
  const double shaped = base <= 0.0 ? (beta == 0.0 ? 1.0 : 0.0) : std::pow(base, beta);
  return (1.0 - 2.0 * epsilon) * shaped + epsilon;
}

double fiber_radius_cdf(double R, double epsilon, double beta) {
  if (R <= 0.0) return 0.0;
  if (R >= 1.0) return 1.0;
  const auto integral = [&](double upper) {
    constexpr int panels = 4096;
    const double h = upper / panels;
    double sum = 0.0;
    for (int i = 0; i <= panels; ++i) {
      const double r = h * i;
      const double w = (i == 0 || i == panels) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
      sum += w * r * fiber_density(r, epsilon, beta);
    }
    return sum * h / 3.0;
  };
  return integral(R) / integral(1.0);
}

std::vector<FiberSeed> sample_ply_cross_section(const YarnParams& yarn, int count, Pcg32& rng) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Delaunay = CGAL::Delaunay_triangulation_2<Kernel>;
  const double min_distance = yarn.fiber_min_spacing * 2.0 * yarn.fiber_radius;
  const double p_max = fiber_density(0.0, yarn.density_epsilon, yarn.density_beta);  // p decreases in R
  std::vector<FiberSeed> seeds;
  seeds.reserve(static_cast<std::size_t>(count));
  Delaunay placed;
  const std::uint64_t max_attempts = 200ULL * static_cast<std::uint64_t>(count) + 10000ULL;
  std::uint64_t attempts = 0;
  while (static_cast<int>(seeds.size()) < count) {
    if (++attempts > max_attempts) {
      fail(
          "yarn '{}': cannot place {} fibres of radius {} mm {} apart in a ply of radius {} mm (placed {}); lower "
          "fiber_count or fiber_min_spacing",
          yarn.preset, count, yarn.fiber_radius, min_distance, yarn.ply_radius, seeds.size());
    }
    // A uniform point in the unit disk (R = √u), accepted with probability p(R)/p_max, has areal
    // density ∝ p(R): the paper's rejection sampler.
    const double R = std::sqrt(rng.uniform());
    const double theta = kTwoPi * rng.uniform();
    if (rng.uniform() * p_max >= fiber_density(R, yarn.density_epsilon, yarn.density_beta)) continue;
    if (min_distance > 0.0) {
      const Kernel::Point_2 q(yarn.ply_radius * yarn.ellipse_n * R * std::cos(theta),
                              yarn.ply_radius * yarn.ellipse_b * R * std::sin(theta));
      if (placed.number_of_vertices() > 0) {
        const auto nearest = placed.nearest_vertex(q);
        if (CGAL::squared_distance(nearest->point(), q) < min_distance * min_distance) continue;
      }
      placed.insert(q);
    }
    seeds.push_back({R, theta});
  }
  return seeds;
}

std::vector<Station> centerline_stations(const Curve& curve, double step) {
  std::vector<Point3> pts = curve.points;
  if (curve.closed && pts.size() > 1) pts.push_back(pts.front());
  // Drop repeated points: they have no tangent.
  std::vector<Point3> clean;
  for (const auto& p : pts) {
    if (clean.empty() || norm(sub(p, clean.back())) > 1e-12) clean.push_back(p);
  }
  std::vector<double> cumulative(clean.size(), 0.0);
  for (std::size_t i = 1; i < clean.size(); ++i) cumulative[i] = cumulative[i - 1] + norm(sub(clean[i], clean[i - 1]));
  const double length = cumulative.empty() ? 0.0 : cumulative.back();
  if (clean.size() < 2 || !(length > step * 1e-3)) fail("yarn centreline: fewer than two distinct points");
  const auto m = static_cast<std::size_t>(std::max(1.0, std::ceil(length / step)));
  std::vector<Station> st(m + 1);
  std::size_t seg = 1;
  for (std::size_t k = 0; k <= m; ++k) {
    const double s = length * static_cast<double>(k) / static_cast<double>(m);
    while (seg + 1 < clean.size() && cumulative[seg] < s) ++seg;
    const double a = cumulative[seg - 1];
    const double b = cumulative[seg];
    st[k].s = s;
    st[k].p = lerp(clean[seg - 1], clean[seg], b > a ? std::clamp((s - a) / (b - a), 0.0, 1.0) : 0.0);
  }
  for (std::size_t k = 0; k <= m; ++k) {
    const Point3 d = (k == 0)   ? sub(st[1].p, st[0].p)
                     : (k == m) ? sub(st[m].p, st[m - 1].p)
                                : sub(st[k + 1].p, st[k - 1].p);
    st[k].t = normalized(d);
  }
  // Initial normal: world z projected off the tangent (so a warp along x has n ≈ z), else y.
  Point3 up{0.0, 0.0, 1.0};
  if (std::abs(dot(up, st[0].t)) > 0.9) up = {0.0, 1.0, 0.0};
  st[0].n = normalized(sub(up, scale(st[0].t, dot(up, st[0].t))));
  for (std::size_t k = 0; k + 1 <= m; ++k) {
    // Double reflection (Wang et al. 2008, Alg. 1).
    const Point3 v1 = sub(st[k + 1].p, st[k].p);
    const double c1 = dot(v1, v1);
    Point3 nL = st[k].n;
    Point3 tL = st[k].t;
    if (c1 > 0.0) {
      nL = sub(st[k].n, scale(v1, 2.0 / c1 * dot(v1, st[k].n)));
      tL = sub(st[k].t, scale(v1, 2.0 / c1 * dot(v1, st[k].t)));
    }
    const Point3 v2 = sub(st[k + 1].t, tL);
    const double c2 = dot(v2, v2);
    Point3 n = c2 > 0.0 ? sub(nL, scale(v2, 2.0 / c2 * dot(v2, nL))) : nL;
    n = normalized(sub(n, scale(st[k + 1].t, dot(n, st[k + 1].t))));
    st[k + 1].n = n;
  }
  for (auto& s : st) s.b = cross(s.t, s.n);
  return st;
}

namespace {

// Frame at arc length s by linear interpolation between uniform stations.
Station frame_at(const std::vector<Station>& st, double s) {
  const double ds = st[1].s - st[0].s;
  const double x = std::clamp(s / ds, 0.0, static_cast<double>(st.size() - 1));
  const auto k = std::min(static_cast<std::size_t>(x), st.size() - 2);
  const double t = x - static_cast<double>(k);
  Station f;
  f.s = s;
  f.p = lerp(st[k].p, st[k + 1].p, t);
  f.t = normalized(lerp(st[k].t, st[k + 1].t, t));
  Point3 n = lerp(st[k].n, st[k + 1].n, t);
  f.n = normalized(sub(n, scale(f.t, dot(n, f.t))));
  f.b = cross(f.t, f.n);
  return f;
}

// Position of a point of ply `ply` at arc length s with ply-normalised radius R and angle θ
// (about the ply centre, measured from the ply's outward direction).
Point3 ply_point(const Station& f, const YarnParams& y, int ply, double R, double theta) {
  const double phi = kTwoPi * ply / y.ply_count + y.ply_twist * kTwoPi * f.s / y.ply_pitch;
  const Point3 u = add(scale(f.n, std::cos(phi)), scale(f.b, std::sin(phi)));
  const Point3 v = add(scale(f.n, -std::sin(phi)), scale(f.b, std::cos(phi)));
  const double a = y.ply_radius * R * y.ellipse_n * std::cos(theta);
  const double b = y.ply_radius * R * y.ellipse_b * std::sin(theta);
  return add(f.p, add(scale(u, y.ply_offset + a), scale(v, b)));
}

struct Loop {
  int fiber = 0;
  double center = 0.0;
  double radius = 1.0;
};

}  // namespace

FiberSet yarn_fibers(const Curve& centerline, const YarnParams& y, std::uint64_t seed, std::int32_t yarn_id) {
  validate(y, "yarn");
  const std::vector<Station> st = centerline_stations(centerline, y.sample_step);
  const double length = st.back().s;
  FiberSet out;
  std::vector<Point3> poly(st.size());
  for (int ply = 0; ply < y.ply_count; ++ply) {
    Pcg32 rng = stream_for(seed, (static_cast<std::uint64_t>(yarn_id) << 8U) | static_cast<std::uint64_t>(ply));
    const std::vector<FiberSeed> seeds = sample_ply_cross_section(y, y.fiber_count, rng);
    std::vector<Loop> loops(static_cast<std::size_t>(event_count(y.loop_density * length, rng)));
    for (auto& l : loops) {
      l.fiber = static_cast<int>(rng.uniform_below(static_cast<std::uint32_t>(y.fiber_count)));
      l.center = length * rng.uniform();
      l.radius = std::max(y.rho_max, normal_deviate(rng, y.loop_radius_mean, y.loop_radius_sd));
    }
    for (int j = 0; j < y.fiber_count; ++j) {
      const FiberSeed& fs = seeds[static_cast<std::size_t>(j)];
      bool has_loop = false;
      for (std::size_t k = 0; k < st.size(); ++k) {
        const double s = st[k].s;
        // Migration (Zhao et al. 2016, Eq. 3), phase from the fibre's own angle as in the paper.
        double R =
            0.5 * fs.R *
            (y.rho_max + y.rho_min + (y.rho_max - y.rho_min) * std::cos(fs.theta + kTwoPi * s / y.migration_period));
        for (const auto& l : loops) {
          if (l.fiber != j) continue;
          const double d = (s - l.center) / y.migration_period;
          if (std::abs(d) < 0.5) {
            // One migration period pulled out to the loop radius with a smooth cos² bump.
            const double w = std::cos(std::numbers::pi * d) * std::cos(std::numbers::pi * d);
            R += w * (l.radius - R);
            has_loop = true;
          }
        }
        const double theta = fs.theta + y.ply_twist * y.fiber_twist * kTwoPi * s / y.fiber_pitch;
        poly[k] = ply_point(st[k], y, ply, R, theta);
      }
      out.add(poly, y.fiber_radius, yarn_id, ply, j, has_loop ? FiberKind::loop : FiberKind::regular);
    }
    const int hairs = event_count(y.hair_density * length, rng);
    for (int h = 0; h < hairs; ++h) {
      const double s0 = length * rng.uniform();
      const double theta0 = kTwoPi * rng.uniform();
      const double rise = std::max(0.0, normal_deviate(rng, y.hair_span_mean, y.hair_span_sd));
      const double turn = normal_deviate(rng, y.hair_angle_span_mean, y.hair_angle_span_sd);
      const double hair_length = std::max(y.sample_step, normal_deviate(rng, y.hair_length_mean, y.hair_length_sd));
      const double s1 = std::min(length, s0 + hair_length);
      const auto n = static_cast<std::size_t>(std::max(1.0, std::ceil((s1 - s0) / y.sample_step)));
      if (!(s1 > s0)) continue;
      std::vector<Point3> hair(n + 1);
      for (std::size_t k = 0; k <= n; ++k) {
        const double t = static_cast<double>(k) / static_cast<double>(n);
        const double s = s0 + t * (s1 - s0);
        // Hair: leaves the ply surface (R = ρmax) and rises linearly while turning about the ply.
        hair[k] = ply_point(frame_at(st, s), y, ply, y.rho_max + t * rise, theta0 + t * turn);
      }
      out.add(hair, y.fiber_radius, yarn_id, ply, y.fiber_count + h, FiberKind::hair);
    }
  }
  return out;
}

}  // namespace weft::cloth
