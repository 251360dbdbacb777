#include "weft/volume/lattice.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/core/rng.h"

namespace weft::volume {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Whole cells covering `span` (a box edge that is a whole number of cells up to rounding
/// gets exactly that many).
std::int64_t cells_over(double span, double h) {
  return std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(span / h - 1e-6)));
}

/// A general direction's frame: e1, e2 ⊥ d, the box's corners projected on them, the lattice
/// origin one cell upstream, the shortest chord (the depth grid's length) and the area of the
/// rays that have it.
void oblique_frame(const WorldBox& box, BeamLattice& L) {
  // The corners relative to lo (0 or the span per axis): projections of small numbers, so the
  // lattice's extent and the chord do not depend on where the box sits.
  const Vec3& size = L.box_size;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Vec3 helper = std::abs(L.d[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  L.e1 = unit_direction(cross(L.d, helper), "beam");
  L.e2 = cross(L.d, L.e1);
  double amin = kInf;
  double amax = -kInf;
  double bmin = kInf;
  double bmax = -kInf;
  double cmin = kInf;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{(c & 1) ? size[0] : 0.0, (c & 2) ? size[1] : 0.0, (c & 4) ? size[2] : 0.0};
    amin = std::min(amin, dot(p, L.e1));
    amax = std::max(amax, dot(p, L.e1));
    bmin = std::min(bmin, dot(p, L.e2));
    bmax = std::max(bmax, dot(p, L.e2));
    cmin = std::min(cmin, dot(p, L.d));
  }
  const double upstream = cmin - L.h;
  for (int a = 0; a < 3; ++a) L.corner_offset[a] = amin * L.e1[a] + bmin * L.e2[a] + upstream * L.d[a];
  for (int a = 0; a < 3; ++a) L.origin[a] = box.lo[a] + L.corner_offset[a];
  L.na = static_cast<std::int64_t>(std::ceil((amax - amin) / L.h - 1e-9));
  L.nb = static_cast<std::int64_t>(std::ceil((bmax - bmin) / L.h - 1e-9));
  L.depth_length = kInf;
  int deep = 0;  // the axis whose two faces set the shortest chord
  for (int a = 0; a < 3; ++a) {
    if (L.d[a] != 0.0 && size[a] / std::abs(L.d[a]) < L.depth_length) {
      L.depth_length = size[a] / std::abs(L.d[a]);
      deep = a;
    }
  }
  // A ray has the whole depth when it enters through face `deep` and leaves through the opposite
  // one: its entry point on that face must lie within size_b − depth·|d_b| of the face's edge
  // along each other axis b, a rectangle that projects onto the plane ⊥ d with the factor |d_deep|.
  L.full_chord_area = std::abs(L.d[deep]);
  for (int b = 0; b < 3; ++b) {
    if (b != deep) L.full_chord_area *= std::max(0.0, size[b] - L.depth_length * std::abs(L.d[b]));
  }
}

}  // namespace

WorldBox active_world_box(const Grid& grid) {
  const IndexBox box = grid.active_bbox();
  if (box.empty()) fail("beam: grid '{}' has no active voxels", grid.name());
  const auto o = grid.origin();
  const double h = grid.voxel_size();
  WorldBox w;
  for (int a = 0; a < 3; ++a) {
    w.lo[a] = o[a] + h * box.min[a];
    w.hi[a] = o[a] + h * (box.max[a] + 1);
    w.span[a] = h * static_cast<double>(box.extent()[static_cast<std::size_t>(a)]);
  }
  return w;
}

std::array<double, 3> unit_direction(const std::array<double, 3>& d, const char* what) {
  double big = 0.0;
  for (double c : d) {
    if (!std::isfinite(c)) fail("{}: direction ({}, {}, {}) is not finite", what, d[0], d[1], d[2]);
    big = std::max(big, std::abs(c));
  }
  if (!(big > 0.0)) fail("{}: direction ({}, {}, {}) has no length", what, d[0], d[1], d[2]);
  // Scaled by the largest component first: its squares neither overflow nor underflow.
  const std::array<double, 3> s{d[0] / big, d[1] / big, d[2] / big};
  const double len = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  return {s[0] / len, s[1] / len, s[2] / len};
}

std::size_t beam_depth_count(double length, double step) {
  // In double until it is known to fit: length/step overflows to ∞ for step = 1e-300, and the
  // conversion of a double beyond size_t is undefined.
  const double n = std::max(1.0, std::ceil(length / step - 1e-9)) + 1.0;
  if (!(n <= kMaxBeamDepths)) {
    fail("beam: depth grid of {:.4g} points (length {:.6g} / depth step {:.6g}) is too fine; the limit is {:.4g}", n,
         length, step, kMaxBeamDepths);
  }
  return static_cast<std::size_t>(n);
}

std::vector<double> beam_depth_grid(double length, double step) {
  const std::size_t count = beam_depth_count(length, step) - 1;
  std::vector<double> d(count + 1);
  for (std::size_t k = 0; k <= count; ++k) d[k] = std::min(static_cast<double>(k) * step, length);
  return d;
}

std::array<double, 3> BeamLattice::ray_offset(std::int64_t i, std::int64_t j, double ja, double jb) const {
  const double a = (static_cast<double>(i) + ja) * h;
  const double b = (static_cast<double>(j) + jb) * h;
  std::array<double, 3> p{};
  for (int c = 0; c < 3; ++c) p[c] = corner_offset[c] + a * e1[c] + b * e2[c];
  return p;
}

std::array<double, 3> BeamLattice::ray_origin(std::int64_t i, std::int64_t j, double ja, double jb) const {
  std::array<double, 3> p = ray_offset(i, j, ja, jb);
  for (int c = 0; c < 3; ++c) p[c] += box_lo[c];
  return p;
}

BeamLattice::Chord BeamLattice::chord(const std::array<double, 3>& offset) const {
  // The slab test in the box's own frame [0, size]: exact for zero direction components.
  Chord c;
  double t0 = -std::numeric_limits<double>::infinity();
  double t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (offset[a] < 0.0 || offset[a] > box_size[a]) return c;
      continue;
    }
    double ta = -offset[a] / d[a];
    double tb = (box_size[a] - offset[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  c.hit = t0 < t1;
  c.t_enter = t0;
  c.t_exit = t1;
  return c;
}

void BeamLattice::require_full_chord_rays(std::uint64_t rays, const std::string& what) const {
  if (!full_chords || rays > 0) return;
  fail(
      "{} with full chords: none of the lattice's rays crosses the box from face to opposite face (those rays cover "
      "an area of {:.3g} across the beam); tilt the direction, add rays per cell, or keep every chord",
      what, full_chord_area);
}

std::string BeamLattice::full_chord_problem() const {
  if (!full_chords) return {};
  const double cell = h * static_cast<double>(stride);
  const double rays = full_chord_area / (cell * cell) * static_cast<double>(per_cell);
  if (rays >= 1.0) return {};
  // Widths below the chord tolerance are a tie of two faces' depths rounded: no area at all.
  if (full_chord_area <= kChordTolerance * depth_length * depth_length) {
    return fmt::format(
        "no ray crosses the box from face to opposite face: the box is as deep ({:.6g}) through two pairs of faces "
        "along this direction (as across a square face at exactly 45 degrees), so only a line of rays has the whole "
        "depth; tilt the direction or keep every chord",
        depth_length);
  }
  return fmt::format(
      "the rays crossing the box from face to opposite face cover an area of {:.3g} across the beam, where "
      "{:.3g} of the lattice's rays fall; tilt the direction, add rays per cell, or keep every chord",
      full_chord_area, rays);
}

bool BeamLattice::keeps(std::int64_t i, std::int64_t j) const {
  // One cell per stride×stride block, at an offset drawn from the block's own stream, so the
  // subset does not depend on the method or the thread.
  if (stride <= 1) return true;
  const std::int64_t s = stride;
  const std::int64_t bi = i / s;
  const std::int64_t bj = j / s;
  const std::int64_t blocks_b = (nb + s - 1) / s;
  Pcg32 rng = stream_for(seed ^ 0x636f6c756d6e73ULL, static_cast<std::uint64_t>(bi * blocks_b + bj));
  const auto pick = static_cast<std::int64_t>(rng.uniform_below(static_cast<std::uint32_t>(s * s)));
  return i - bi * s == pick / s && j - bj * s == pick % s;
}

CellOffsets BeamLattice::offsets(std::int64_t i, std::int64_t j) const {
  return {seed, static_cast<std::uint64_t>(i) * static_cast<std::uint64_t>(nb) + static_cast<std::uint64_t>(j), jitter};
}

namespace {

/// The lattice without the full-chord refusal (make_beam_lattice's layout).
BeamLattice lay_out(const WorldBox& box, double h, const BeamSpec& spec, bool with_depths) {
  require_positive("beam: cell width", h);
  BeamLattice L;
  L.d = unit_direction(spec.direction, "beam");
  L.axis = beam_axis(spec.direction);
  L.h = h;
  L.per_cell = spec.rays_per_column;
  L.jitter = spec.jitter || spec.rays_per_column > 1;
  L.seed = spec.seed;
  L.stride = spec.column_stride;
  L.full_chords = spec.full_chords && L.axis < 0;
  L.box_lo = box.lo;
  for (int a = 0; a < 3; ++a) L.box_size[a] = box.size(a);
  const double step = spec.depth_step > 0.0 ? spec.depth_step : L.h;
  if (L.axis >= 0) {
    const int a = L.axis;
    const int ua = (a + 1) % 3;
    const int va = (a + 2) % 3;
    L.e1 = {0, 0, 0};
    L.e2 = {0, 0, 0};
    L.e1[ua] = 1.0;
    L.e2[va] = 1.0;
    L.corner_offset = {0.0, 0.0, 0.0};
    if (L.d[a] < 0.0) L.corner_offset[a] = L.box_size[a];
    L.origin = box.lo;
    if (L.d[a] < 0.0) L.origin[a] = box.hi[a];
    L.na = cells_over(box.size(ua), h);
    L.nb = cells_over(box.size(va), h);
    L.depth_length = box.size(a);
    L.full_chord_area = box.size(ua) * box.size(va);
  } else {
    oblique_frame(box, L);
  }
  L.depth_step = step;
  L.depth_count = beam_depth_count(L.depth_length, step);
  if (with_depths) L.depths = beam_depth_grid(L.depth_length, step);
  return L;
}

}  // namespace

BeamLattice make_beam_lattice(const WorldBox& box, double h, const BeamSpec& spec, bool with_depths) {
  // Refused before anything is traced (every beam's estimate lays its lattice out): a beam that
  // would keep no ray (docs/validate.md "Full chords").
  if (const std::string why = full_chord_problem(box, h, spec); !why.empty())
    fail("beam {} with full chords: {}", direction_label(spec.direction), why);
  return lay_out(box, h, spec, with_depths);
}

std::string full_chord_problem(const WorldBox& box, double h, const BeamSpec& spec) {
  if (!spec.full_chords) return {};
  return lay_out(box, h, spec, false).full_chord_problem();
}

}  // namespace weft::volume
