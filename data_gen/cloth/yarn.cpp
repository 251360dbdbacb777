#include "data_gen/cloth/yarn.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>

// CGAL is here for the minimum-distance fibre placement: a Delaunay triangulation answers
// "nearest placed fibre to this candidate" in O(log n) expected time with exact predicates, which
// keeps rejection sampling of a few thousand fibres per ply cheap and robust (no hand-rolled grid
// whose cell size would have to track the ellipse and the spacing).
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "weft/core/error.h"
#include "weft/core/parallel.h"

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
// mean is exact and a density of 0 gives none. The estimate (estimate.h) refuses counts past any
// memory first; a direct caller past 2⁵³ is refused here, where the count would stop being exact.
std::uint64_t event_count(double expected, Pcg32& rng, const YarnParams& y, const char* what) {
  if (!(expected < 0x1p53))
    fail("yarn '{}': {:.3g} {} in one piece of yarn, far beyond any memory (lower its density)", y.preset, expected,
         what);
  const double whole = std::floor(expected);
  return static_cast<std::uint64_t>(whole) + (rng.uniform() < expected - whole ? 1U : 0U);
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

namespace {

/// A centreline's points without repeats (they have no tangent), closed curves closed, and the
/// arc length at each.
struct CleanCenterline {
  std::vector<Point3> points;
  std::vector<double> cumulative;
  double length() const { return cumulative.empty() ? 0.0 : cumulative.back(); }
};

CleanCenterline clean_centerline(const Curve& curve) {
  std::vector<Point3> pts = curve.points;
  if (curve.closed && pts.size() > 1) pts.push_back(pts.front());
  CleanCenterline c;
  for (const auto& p : pts) {
    if (c.points.empty() || norm(sub(p, c.points.back())) > 1e-12) c.points.push_back(p);
  }
  c.cumulative.assign(c.points.size(), 0.0);
  for (std::size_t i = 1; i < c.points.size(); ++i)
    c.cumulative[i] = c.cumulative[i - 1] + norm(sub(c.points[i], c.points[i - 1]));
  return c;
}

std::string centerline_problem(const CleanCenterline& c, double step) {
  if (c.points.size() < 2) return "has fewer than two distinct points (points closer than 1e-12 mm count as one)";
  if (!(c.length() > step * 1e-3))
    return fmt::format("is {:.3g} mm long, under a thousandth of the yarn's sample step {:.3g} mm", c.length(), step);
  return {};
}

}  // namespace

std::string centerline_problem(const Curve& curve, double step) {
  return centerline_problem(clean_centerline(curve), step);
}

std::vector<Station> centerline_stations(const Curve& curve, double step) {
  const CleanCenterline c = clean_centerline(curve);
  if (const auto why = centerline_problem(c, step); !why.empty()) fail("yarn centreline {}", why);
  const std::vector<Point3>& clean = c.points;
  const std::vector<double>& cumulative = c.cumulative;
  const double length = c.length();
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

// A loop flyaway: one migration period of fibre `fiber` around arc length `center` pulled out to
// `radius` (× ply radius); `order` is its draw index in the ply, the order loops apply in.
struct Loop {
  int fiber = 0;
  double center = 0.0;
  double radius = 1.0;
  std::size_t order = 0;
};

// A hair flyaway, drawn before any point is made so that the output layout is known up front.
struct Hair {
  double s0 = 0.0;
  double s1 = 0.0;
  double theta0 = 0.0;
  double rise = 0.0;
  double turn = 0.0;
  std::size_t segments = 0;
};

struct PlyPlan {
  std::vector<FiberSeed> seeds;
  std::vector<std::vector<Loop>> loops;  // per fibre, sorted by centre
  std::vector<std::uint8_t> has_loop;    // per fibre: some station lies inside one of its loops
  std::vector<Hair> hairs;               // in draw order (pieces in order)
  std::uint64_t loop_count = 0;          // loops drawn
};

struct YarnPlan {
  const YarnParams* y = nullptr;
  std::int32_t yarn_id = 0;
  std::vector<Station> st;
  std::size_t pieces = 0;
  std::vector<PlyPlan> plies;
  std::uint64_t first_fiber = 0;  // index of the yarn's first polyline in the output
  std::uint64_t first_point = 0;
};

// Stream of piece `piece` of ply `ply`: piece 0 continues the ply's own stream (after its
// cross-section), so a yarn of one piece draws exactly what it drew before yarns were cut into
// pieces; later pieces get streams of their own, keyed apart from every ply stream by the top bit.
Pcg32 piece_stream(std::uint64_t seed, std::int32_t yarn_id, int ply, std::size_t piece) {
  return stream_for(seed, (1ULL << 63U) | (static_cast<std::uint64_t>(yarn_id) << 32U) |
                              (static_cast<std::uint64_t>(ply) << 24U) | static_cast<std::uint64_t>(piece));
}

// Arc length range of piece p.
std::pair<double, double> piece_span(const YarnPlan& plan, std::size_t p) {
  const double a = plan.st[p * kPieceStations].s;
  const double b = p + 1 == plan.pieces ? plan.st.back().s : plan.st[(p + 1) * kPieceStations].s;
  return {a, b};
}

// The yarn's stations (the frames its points are made on) and pieces; the random part follows in
// plan_flyaways, once the points to make are known to the progress report.
YarnPlan plan_stations(const Curve& centerline, const YarnParams& y, std::int32_t yarn_id) {
  validate(y, "yarn");
  YarnPlan plan;
  plan.y = &y;
  plan.yarn_id = yarn_id;
  plan.st = centerline_stations(centerline, y.sample_step);
  plan.pieces = (plan.st.size() - 1 + kPieceStations - 1) / kPieceStations;
  return plan;
}

bool by_centre(const Loop& u, const Loop& v) { return u.center != v.center ? u.center < v.center : u.order < v.order; }

// Draws the random part of a yarn (cross-sections, loops, hairs): O(fibres + flyaways), serial
// per yarn and cheap next to the points unless the loops are dense; `task` is asked whether to go
// on every kReportSteps flyaways.
void plan_flyaways(YarnPlan& plan, std::uint64_t seed, ProgressTask& task) {
  const YarnParams& y = *plan.y;
  const std::int32_t yarn_id = plan.yarn_id;
  const double P = y.migration_period;
  const double ds = plan.st[1].s - plan.st[0].s;
  const std::size_t m = plan.st.size() - 1;
  plan.plies.resize(static_cast<std::size_t>(y.ply_count));
  for (int ply = 0; ply < y.ply_count; ++ply) {
    PlyPlan& pp = plan.plies[static_cast<std::size_t>(ply)];
    Pcg32 rng = stream_for(seed, (static_cast<std::uint64_t>(yarn_id) << 8U) | static_cast<std::uint64_t>(ply));
    pp.seeds = sample_ply_cross_section(y, y.fiber_count, rng);
    pp.loops.resize(static_cast<std::size_t>(y.fiber_count));
    pp.has_loop.assign(static_cast<std::size_t>(y.fiber_count), 0);
    std::size_t order = 0;
    std::uint64_t drawn = 0;
    std::vector<std::size_t> before(static_cast<std::size_t>(y.fiber_count));
    for (std::size_t p = 0; p < plan.pieces; ++p) {
      Pcg32 piece_rng = p == 0 ? rng : piece_stream(seed, yarn_id, ply, p);
      const auto [a, b] = piece_span(plan, p);
      for (std::size_t j = 0; j < before.size(); ++j) before[j] = pp.loops[j].size();
      const std::uint64_t loops = event_count(y.loop_density * (b - a), piece_rng, y, "loop flyaways");
      for (std::uint64_t i = 0; i < loops; ++i) {
        if (++drawn % kReportSteps == 0) task.step(0);
        Loop l;
        l.fiber = static_cast<int>(piece_rng.uniform_below(static_cast<std::uint32_t>(y.fiber_count)));
        l.center = a + (b - a) * piece_rng.uniform();
        l.radius = std::max(y.rho_max, normal_deviate(piece_rng, y.loop_radius_mean, y.loop_radius_sd));
        l.order = order++;
        pp.loops[static_cast<std::size_t>(l.fiber)].push_back(l);
      }
      // Each fibre's loops sorted by centre, piece by piece: a piece's centres lie in [a, b] and
      // the next piece's in [b, …], so the runs join into the order one sort of all would give.
      for (std::size_t j = 0; j < before.size(); ++j) {
        auto& mine = pp.loops[j];
        std::sort(mine.begin() + static_cast<std::ptrdiff_t>(before[j]), mine.end(), by_centre);
      }
      task.step(0);
      const std::uint64_t hairs = event_count(y.hair_density * (b - a), piece_rng, y, "hair flyaways");
      for (std::uint64_t h = 0; h < hairs; ++h) {
        if (++drawn % kReportSteps == 0) task.step(0);
        Hair hair;
        hair.s0 = a + (b - a) * piece_rng.uniform();
        hair.theta0 = kTwoPi * piece_rng.uniform();
        hair.rise = std::max(0.0, normal_deviate(piece_rng, y.hair_span_mean, y.hair_span_sd));
        hair.turn = normal_deviate(piece_rng, y.hair_angle_span_mean, y.hair_angle_span_sd);
        const double hair_length =
            std::max(y.sample_step, normal_deviate(piece_rng, y.hair_length_mean, y.hair_length_sd));
        hair.s1 = std::min(plan.st.back().s, hair.s0 + hair_length);
        if (!(hair.s1 > hair.s0)) continue;
        hair.segments = static_cast<std::size_t>(std::max(1.0, std::ceil((hair.s1 - hair.s0) / y.sample_step)));
        pp.hairs.push_back(hair);
      }
    }
    pp.loop_count = order;
    // A fibre is a loop fibre when a station falls inside one of its loops; only the stations
    // within half a period of each centre need checking (same test as the point pass).
    for (auto& loops : pp.loops) {
      for (const Loop& l : loops) {
        const auto k0 = static_cast<std::size_t>(std::max(0.0, std::floor((l.center - 0.5 * P) / ds) - 1.0));
        const auto k1 =
            std::min(m, static_cast<std::size_t>(std::max(0.0, std::ceil((l.center + 0.5 * P) / ds) + 1.0)));
        for (std::size_t k = k0; k <= k1 && !pp.has_loop[static_cast<std::size_t>(l.fiber)]; ++k) {
          if (std::abs((plan.st[k].s - l.center) / P) < 0.5) pp.has_loop[static_cast<std::size_t>(l.fiber)] = 1;
        }
      }
    }
  }
}

// Fills stations [k0, k1) of every regular fibre of `ply`, and every hair drawn in piece `piece`,
// into the output arrays at their planned places.
void fill_piece(const YarnPlan& plan, int ply, std::size_t piece, const std::vector<std::uint64_t>& hair_first,
                std::size_t hair_begin, std::size_t hair_end, std::uint64_t ply_point0, Point3* points,
                ProgressTask& task) {
  const YarnParams& y = *plan.y;
  const PlyPlan& pp = plan.plies[static_cast<std::size_t>(ply)];
  const std::size_t n_st = plan.st.size();
  const std::size_t k0 = piece * kPieceStations;
  const std::size_t k1 = piece + 1 == plan.pieces ? n_st : k0 + kPieceStations;
  const double half = 0.5 * y.migration_period;
  const auto by_order = [](const Loop* u, const Loop* v) { return u->order < v->order; };
  // The loops over the current point in draw order (the order they apply in), and a scratch list.
  std::vector<const Loop*> active;
  std::vector<const Loop*> merged;
  std::uint64_t work = 0;  // steps since the last report (yarn_cost's unit)
  std::uint64_t made = 0;  // regular fibre points made since then
  for (int j = 0; j < y.fiber_count; ++j) {
    const FiberSeed& fs = pp.seeds[static_cast<std::size_t>(j)];
    const std::vector<Loop>& loops = pp.loops[static_cast<std::size_t>(j)];
    Point3* out = points + ply_point0 + static_cast<std::uint64_t>(j) * n_st;
    // Loops sorted by centre: [lo, hi) are those within half a period of s, widened by a relative
    // margin so that every loop the test |d| < 0.5 below accepts is in despite rounding; `active`
    // holds them in draw order, updated as s moves on (those left behind dropped, those reached
    // merged in), so a point costs 1 + its loops. Sorting them at every point cost a log factor
    // more, over a window of a whole period each side (twice the loops).
    const auto margin = [half](double s) { return 1e-9 * (half + std::abs(s)); };
    const double s0 = plan.st[k0].s;
    auto lo = std::lower_bound(loops.begin(), loops.end(), s0 - half - margin(s0),
                               [](const Loop& l, double c) { return l.center < c; });
    auto hi = lo;
    active.clear();
    for (std::size_t k = k0; k < k1; ++k) {
      const double s = plan.st[k].s;
      // Migration (Zhao et al. 2016, Eq. 3), phase from the fibre's own angle as in the paper.
      double R =
          0.5 * fs.R *
          (y.rho_max + y.rho_min + (y.rho_max - y.rho_min) * std::cos(fs.theta + kTwoPi * s / y.migration_period));
      const double low = s - half - margin(s);
      if (lo != loops.end() && lo->center < low) {
        while (lo != loops.end() && lo->center < low) ++lo;
        hi = std::max(hi, lo);
        std::erase_if(active, [low](const Loop* l) { return l->center < low; });
      }
      const auto reached = hi;
      while (hi != loops.end() && hi->center <= s + half + margin(s)) ++hi;
      if (hi != reached) {
        const auto kept = static_cast<std::ptrdiff_t>(active.size());
        for (auto it = reached; it != hi; ++it) active.push_back(&*it);
        std::sort(active.begin() + kept, active.end(), by_order);
        merged.clear();
        std::merge(active.begin(), active.begin() + kept, active.begin() + kept, active.end(),
                   std::back_inserter(merged), by_order);
        active.swap(merged);
      }
      for (const Loop* l : active) {
        const double d = (s - l->center) / y.migration_period;
        if (std::abs(d) < 0.5) {
          // One migration period pulled out to the loop radius with a smooth cos² bump.
          const double w = std::cos(std::numbers::pi * d) * std::cos(std::numbers::pi * d);
          R += w * (l->radius - R);
        }
      }
      const double theta = fs.theta + y.ply_twist * y.fiber_twist * kTwoPi * s / y.fiber_pitch;
      out[k] = ply_point(plan.st[k], y, ply, R, theta);
      ++made;
      work += 1 + active.size();
      if (work >= kReportSteps) {
        task.step(made);
        made = work = 0;
      }
    }
  }
  for (std::size_t h = hair_begin; h < hair_end; ++h) {
    const Hair& hair = pp.hairs[h];
    Point3* out = points + hair_first[h];
    for (std::size_t k = 0; k <= hair.segments; ++k) {
      const double t = static_cast<double>(k) / static_cast<double>(hair.segments);
      const double s = hair.s0 + t * (hair.s1 - hair.s0);
      // Hair: leaves the ply surface (R = ρmax) and rises linearly while turning about the ply.
      out[k] = ply_point(frame_at(plan.st, s), y, ply, y.rho_max + t * hair.rise, hair.theta0 + t * hair.turn);
    }
    work += hair.segments + 1;
    if (work >= kReportSteps) {
      task.step(made);
      made = work = 0;
    }
  }
  task.step(made);
}

}  // namespace

FiberSet build_yarns(const std::vector<YarnJob>& jobs, std::uint64_t seed, ProgressSink& progress) {
  std::vector<YarnPlan> plans(jobs.size());
  parallel_units(jobs.size(), [&](std::size_t i) {
    plans[i] = plan_stations(*jobs[i].centerline, *jobs[i].params, jobs[i].yarn_id);
  });
  // One unit of progress per regular fibre point (hairs are a small share of any yarn's points).
  std::uint64_t regular_points = 0;
  for (const auto& plan : plans)
    regular_points += static_cast<std::uint64_t>(plan.y->ply_count) * static_cast<std::uint64_t>(plan.y->fiber_count) *
                      plan.st.size();
  ProgressTask task(progress, "generating fibres", regular_points);
  parallel_units(plans.size(), [&](std::size_t i) { plan_flyaways(plans[i], seed, task); });
  // Layout: per yarn, per ply, the regular fibres (one point per station) then the hairs. Every
  // polyline's place is known before any point is made, so pieces write straight into the output.
  FiberSet out;
  std::uint64_t fibers = 0;
  std::uint64_t points = 0;
  for (auto& plan : plans) {
    plan.first_fiber = fibers;
    plan.first_point = points;
    for (const auto& pp : plan.plies) {
      out.loops += pp.loop_count;
      fibers += pp.seeds.size() + pp.hairs.size();
      points += pp.seeds.size() * plan.st.size();
      for (const auto& h : pp.hairs) points += h.segments + 1;
    }
  }
  out.points.resize(points);
  out.offsets.resize(fibers + 1);
  out.radius.resize(fibers);
  out.yarn.resize(fibers);
  out.ply.resize(fibers);
  out.fiber.resize(fibers);
  out.kind.resize(fibers);
  // Work units: (yarn, ply, piece); each knows where its points go.
  struct Unit {
    std::size_t yarn;
    int ply;
    std::size_t piece;
    std::uint64_t ply_point0;
    std::size_t hair_begin;
    std::size_t hair_end;
  };
  std::vector<Unit> units;
  std::vector<std::vector<std::vector<std::uint64_t>>> hair_first(plans.size());
  {
    std::uint64_t f = 0;
    std::uint64_t p = 0;
    for (std::size_t i = 0; i < plans.size(); ++i) {
      const YarnPlan& plan = plans[i];
      const YarnParams& y = *plan.y;
      hair_first[i].resize(plan.plies.size());
      for (int ply = 0; ply < y.ply_count; ++ply) {
        const PlyPlan& pp = plan.plies[static_cast<std::size_t>(ply)];
        const std::uint64_t ply_point0 = p;
        for (int j = 0; j < y.fiber_count; ++j) {
          out.offsets[f] = p;
          out.radius[f] = y.fiber_radius;
          out.yarn[f] = plan.yarn_id;
          out.ply[f] = ply;
          out.fiber[f] = j;
          out.kind[f] = pp.has_loop[static_cast<std::size_t>(j)] ? FiberKind::loop : FiberKind::regular;
          ++f;
          p += plan.st.size();
        }
        auto& firsts = hair_first[i][static_cast<std::size_t>(ply)];
        firsts.reserve(pp.hairs.size());
        for (std::size_t h = 0; h < pp.hairs.size(); ++h) {
          firsts.push_back(p);
          out.offsets[f] = p;
          out.radius[f] = y.fiber_radius;
          out.yarn[f] = plan.yarn_id;
          out.ply[f] = ply;
          out.fiber[f] = y.fiber_count + static_cast<std::int32_t>(h);
          out.kind[f] = FiberKind::hair;
          ++f;
          p += pp.hairs[h].segments + 1;
        }
        // Hairs go with the piece their root lies in (they are drawn in piece order).
        std::size_t h = 0;
        for (std::size_t piece = 0; piece < plan.pieces; ++piece) {
          const double end = piece_span(plan, piece).second;
          const std::size_t begin = h;
          while (h < pp.hairs.size() && (piece + 1 == plan.pieces || pp.hairs[h].s0 < end)) ++h;
          units.push_back({i, ply, piece, ply_point0, begin, h});
        }
      }
    }
    out.offsets[f] = p;
  }
  parallel_units(units.size(), [&](std::size_t u) {
    const Unit& unit = units[u];
    fill_piece(plans[unit.yarn], unit.ply, unit.piece, hair_first[unit.yarn][static_cast<std::size_t>(unit.ply)],
               unit.hair_begin, unit.hair_end, unit.ply_point0, out.points.data(), task);
  });
  return out;
}

double loop_coverage(const YarnParams& y) { return y.loop_density * y.migration_period / y.fiber_count; }

double mean_of_floored_normal(double floor, double mean, double sd) {
  if (!(sd > 0.0)) return std::max(floor, mean);
  const double z = (floor - mean) / sd;
  const double cdf = 0.5 * std::erfc(-z / std::numbers::sqrt2);
  const double pdf = std::exp(-0.5 * z * z) / std::sqrt(kTwoPi);
  return mean + (floor - mean) * cdf + sd * pdf;
}

YarnCost yarn_cost(const YarnParams& y, double length) {
  YarnCost c;
  const double plies = y.ply_count;
  const double fibres = y.fiber_count;
  c.stations = std::max(1.0, std::ceil(length / y.sample_step)) + 1.0;
  c.loops = plies * y.loop_density * length;
  c.hairs = plies * y.hair_density * length;
  c.hair_length = std::min(length, mean_of_floored_normal(y.sample_step, y.hair_length_mean, y.hair_length_sd));
  // A hair has ⌈length/step⌉ segments (at least one), so on average ⌈mean/step⌉ + ½ + 1 points.
  const double hair_points = std::ceil(std::max(c.hair_length, y.sample_step) / y.sample_step) + 1.5;
  const double regular_points = plies * fibres * c.stations;
  c.points = regular_points + c.hairs * hair_points;
  // Bytes held while the points are made: the stations; per loop a Loop and per hair a Hair and
  // its first point's index, all twice for the vectors' growth; per regular fibre its seed, its
  // loop list and its loop flag.
  c.loop_bytes = 2.0 * c.loops * sizeof(Loop);
  c.plan_bytes = c.stations * sizeof(Station) + c.loop_bytes + 2.0 * c.hairs * (sizeof(Hair) + sizeof(std::uint64_t)) +
                 plies * fibres * (sizeof(FiberSeed) + sizeof(std::vector<Loop>) + 1.0);
  // Steps, each about as costly as a voxel read of a pass over a grid (volume/pass_budget.h): a
  // point made (and looked at once more for the loop flags); at each regular point its loops,
  // c = loop_coverage on average, kept in draw order and blended, 4 steps each (measured: 6 ns a
  // loop at a point, where a pass reads a voxel in 3 ns; docs/cloth.md "Estimate before
  // spending"); each loop drawn and sorted among its fibre's loops of its piece.
  const double per_fibre_piece = c.loops / (plies * fibres) * std::min(1.0, kPieceStations * y.sample_step / length);
  c.loop_steps = regular_points * 4.0 * loop_coverage(y) + c.loops * (1.0 + std::log2(1.0 + per_fibre_piece));
  c.steps = c.points + regular_points + c.loop_steps;
  return c;
}

FiberSet yarn_fibers(const Curve& centerline, const YarnParams& y, std::uint64_t seed, std::int32_t yarn_id) {
  return build_yarns({YarnJob{&centerline, &y, yarn_id}}, seed);
}

}  // namespace weft::cloth
