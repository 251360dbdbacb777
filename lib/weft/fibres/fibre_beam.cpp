#include "weft/fibres/fibre_beam.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/volume/curve_sums.h"
#include "weft/volume/pass_budget.h"

namespace weft::fibres {
namespace {

constexpr std::size_t kShards = 64;  // fixed, so the sums do not depend on the thread count

}  // namespace

volume::WorldBox fibre_box(const CapsuleIndex& fibres) {
  if (fibres.capsule_count() == 0) fail("fibre beam: there are no fibres");
  return {fibres.lo(), fibres.hi()};
}

void check_fibre_beam(const volume::WorldBox& box, double cell, const volume::BeamSpec& spec) {
  // The box as given (not a grid's): an inverted or non-finite one would give a lattice of one
  // cell and negative depths (T = 1 at "depth −1"), so it is refused as Grid.to_numpy refuses
  // an inverted index box.
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    if (!std::isfinite(box.lo[i]) || !std::isfinite(box.hi[i]))
      fail("fibre beam: box corners must be finite, got ({}, {}, {})..({}, {}, {})", box.lo[0], box.lo[1], box.lo[2],
           box.hi[0], box.hi[1], box.hi[2]);
    if (box.lo[i] > box.hi[i])
      fail("fibre beam: box min must be <= max per axis, got ({}, {}, {})..({}, {}, {})", box.lo[0], box.lo[1],
           box.lo[2], box.hi[0], box.hi[1], box.hi[2]);
  }
  require_positive("fibre beam: cell width", cell);
  // The budget of every pass (volume/pass_budget.h), before the depths are allocated: a ray
  // costs its BVH walk, bounded like a voxel ray's cell crossings, and its profile's depths.
  const volume::BeamLattice plan = volume::make_beam_lattice(box, cell, spec, false);
  const auto s = static_cast<double>(plan.stride);
  const double rays = std::ceil(static_cast<double>(plan.na) / s) * std::ceil(static_cast<double>(plan.nb) / s) *
                      static_cast<double>(plan.per_cell);
  const auto K = static_cast<double>(plan.depth_count);
  volume::check_pass_cost(
      fmt::format("fibre beam {} ({:.4g} rays)", volume::direction_label(plan.d), rays), "the fibres",
      {rays * (plan.cells_crossed() + K), (3.0 * static_cast<double>(kShards) + 4.0) * K * sizeof(double)});
}

void check_fibre_beam(const volume::Grid& grid, const volume::BeamSpec& spec) {
  check_fibre_beam(volume::active_world_box(grid), grid.voxel_size(), spec);
}

volume::TransmittanceCurve measure_fibre_beam(const CapsuleIndex& fibres, const volume::Grid& grid,
                                              const volume::BeamSpec& spec, double extinction, ProgressSink& progress) {
  return measure_fibre_beam(fibres, volume::active_world_box(grid), grid.voxel_size(), spec, extinction, progress);
}

volume::TransmittanceCurve measure_fibre_beam(const CapsuleIndex& fibres, const volume::WorldBox& box, double cell,
                                              const volume::BeamSpec& spec, double extinction, ProgressSink& progress) {
  if (spec.rays_per_column < 1) fail("fibre beam: rays per cell must be >= 1, got {}", spec.rays_per_column);
  if (spec.column_stride < 1 || spec.column_stride > 4096)
    fail("fibre beam: column stride must be in 1..4096, got {}", spec.column_stride);
  if (spec.depth_step != 0.0) require_positive("fibre beam: depth step", spec.depth_step);
  if (std::isnan(extinction) || extinction < 0.0)
    fail("fibre beam: extinction inside the fibres must be >= 0 (or infinite: opaque), got {}", extinction);
  const bool opaque = std::isinf(extinction);
  check_fibre_beam(box, cell, spec);
  const volume::BeamLattice L = volume::make_beam_lattice(box, cell, spec);
  const std::size_t K = L.depths.size();
  const auto units = static_cast<std::size_t>(L.na);
  const std::size_t shards = std::min(kShards, units);
  std::vector<volume::CurveSums> parts(shards, volume::CurveSums(K));
  ProgressTask task(progress, "fibre beam " + volume::direction_label(L.d), units);
  parallel_units(shards, [&](std::size_t shard) {
    volume::CurveSums& sum = parts[shard];
    std::vector<Interval> hits;
    std::vector<std::uint64_t> blocked(K + 1, 0);  // opaque: rays whose first entry lies before depth k
    const std::size_t begin = shard * units / shards;
    const std::size_t end = (shard + 1) * units / shards;
    L.for_each_ray(
        begin, end,
        [&](const Point3& offset, std::int64_t, std::int64_t, int) {
          double t_in = 0.0;
          double t_out = L.depths.back();
          if (L.axis < 0) {
            // The chord in the box's own frame, as the voxel beam takes it (lattice.h): the same
            // rays kept wherever the box sits.
            const volume::BeamLattice::Chord c = L.chord(offset);
            if (!L.traces_chord(c)) return;
            t_in = c.t_enter;
            t_out = c.t_exit;
          }
          Point3 o{};
          for (int a = 0; a < 3; ++a) o[a] = L.box_lo[a] + offset[a];
          hits.clear();
          fibres.intersect(o, L.d, t_in, t_out, hits);
          ++sum.n;
          if (opaque) {
            // T_i(t) = 1 up to the first entry, 0 after: counted by the first depth past it.
            double first = 1e300;
            for (const Interval& h : hits) first = std::min(first, h[0] - t_in);
            const auto k =
                static_cast<std::size_t>(std::upper_bound(L.depths.begin(), L.depths.end(), first) - L.depths.begin());
            ++blocked[k];
            return;
          }
          // The union of the intervals (sorted by entry, overlaps merged), then τ at each depth.
          std::sort(hits.begin(), hits.end());
          double covered = 0.0;  // length of the union before the current interval
          std::size_t h = 0;
          Interval cur{0.0, -1.0};
          const auto next_union = [&]() {
            if (h >= hits.size()) return false;
            cur = hits[h++];
            while (h < hits.size() && hits[h][0] <= cur[1]) cur[1] = std::max(cur[1], hits[h++][1]);
            cur[0] -= t_in;
            cur[1] -= t_in;
            return true;
          };
          bool more = next_union();
          double tau_prev = -1.0;
          double e_prev = 1.0;
          for (std::size_t k = 0; k < K; ++k) {
            const double t = L.depths[k];
            while (more && cur[1] <= t) {
              covered += cur[1] - cur[0];
              more = next_union();
            }
            const double inside = more && cur[0] < t ? t - cur[0] : 0.0;
            const double tau = extinction * (covered + inside);
            if (tau != tau_prev) {
              e_prev = std::exp(-tau);
              tau_prev = tau;
            }
            sum.s1[k] += e_prev;
            sum.s2[k] += e_prev * e_prev;
          }
        },
        [&] { task.step(); });
    if (opaque) {
      // Rays whose first entry is at depth ≥ t_k (upper_bound index > k) still see T = 1 there.
      std::uint64_t through = sum.n;
      for (std::size_t k = 0; k < K; ++k) {
        through -= blocked[k];
        sum.s1[k] = static_cast<double>(through);
        sum.s2[k] = static_cast<double>(through);
      }
    }
  });
  std::uint64_t traced = 0;
  for (const volume::CurveSums& p : parts) traced += p.n;
  L.require_full_chord_rays(traced, "fibre beam " + volume::direction_label(L.d));
  return volume::curve_of_sums(parts, L.depths, L.d,
                               opaque ? "fibres (opaque)" : fmt::format("fibres (extinction {:.6g})", extinction),
                               "fibre beam " + volume::direction_label(L.d));
}

}  // namespace weft::fibres

namespace weft::fibres {

CurveDifference curve_difference(const volume::TransmittanceCurve& a, const volume::TransmittanceCurve& b) {
  if (a.size() != b.size() || a.size() == 0) fail("curve difference: {} depths against {}", a.size(), b.size());
  CurveDifference d;
  double sq = 0.0;
  double se_a = 0.0;
  double se_b = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (std::abs(a.depth[k] - b.depth[k]) > 1e-9 * std::max(1.0, std::abs(a.depth[k])))
      fail("curve difference: depth {} is {} against {}", k, a.depth[k], b.depth[k]);
    const double ta = a.transmittance(k);
    const double tb = b.transmittance(k);
    sq += (ta - tb) * (ta - tb);
    d.max_abs = std::max(d.max_abs, std::abs(ta - tb));
    se_a += a.stderr_abs(k) * a.stderr_abs(k);
    se_b += b.stderr_abs(k) * b.stderr_abs(k);
  }
  const auto n = static_cast<double>(a.size());
  d.rms = std::sqrt(sq / n);
  d.rms_stderr_a = std::sqrt(se_a / n);
  d.rms_stderr_b = std::sqrt(se_b / n);
  d.end_a = a.transmittance(a.size() - 1);
  d.end_b = b.transmittance(b.size() - 1);
  return d;
}

}  // namespace weft::fibres
