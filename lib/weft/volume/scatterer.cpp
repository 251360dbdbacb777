#include "weft/volume/scatterer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include <tbb/parallel_sort.h>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/volume/beam_accumulate_impl.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/lattice.h"
#include "weft/volume/pass_budget.h"

namespace weft::volume {
namespace {

using Vec3 = std::array<double, 3>;
using detail::kMaxShards;
using detail::LseAccumulator;

constexpr std::uint64_t kChunk = 1024;  // rays per work unit

/// A voxel or tile of the particle origins' table and its cumulative weight (value × voxels).
struct ParticleCell {
  openvdb::CoordBBox box;
  double cdf = 0.0;
};

/// What a request resolves to before any work: its direction, the rays' length and depth grid.
struct ScattererPlan {
  Vec3 fixed{0.0, 0.0, 1.0};
  double diagonal = 0.0;
  double max_depth = 0.0;
  double depth_step = 0.0;
};

ScattererPlan plan_of(const Grid& grid, const ScattererSpec& spec) {
  require_positive("scatterer rays: scale (sigma)", spec.scale);
  if (spec.rays < kMinScattererRays)
    fail("scatterer rays: need at least {} rays, got {}", kMinScattererRays, spec.rays);
  if (grid.active_voxel_count() == 0) fail("scatterer rays: grid '{}' has no active voxels", grid.name());
  ScattererPlan p;
  if (spec.fixed_direction) p.fixed = unit_direction(spec.direction, "scatterer rays");
  const double h = grid.voxel_size();
  const auto ext = grid.active_bbox().extent();
  for (int a = 0; a < 3; ++a) p.diagonal += std::pow(h * static_cast<double>(ext[a]), 2);
  p.diagonal = std::sqrt(p.diagonal);
  p.max_depth = spec.max_depth > 0.0 ? spec.max_depth : p.diagonal;
  p.depth_step = spec.depth_step > 0.0 ? spec.depth_step : h;
  return p;
}

/// Upper bounds, as volume::estimate_beam's for a ray-by-ray beam (docs/robustness.md "Work and
/// memory budgets"): each of the 2 x rays rays (one from a particle, one from a uniform point)
/// crosses at most chord·(|dx| + |dy| + |dz|)/h + 3 cells (|dx| + |dy| + |dz| <= √3 for any
/// direction) and profiles every depth; the origins' table holds a box and a weight per active
/// value (twice that while its vector grows), every shard two accumulators of 3 sums per depth.
PassCost scatterer_cost(const Grid& grid, const ScattererSpec& spec, const ScattererPlan& p) {
  const auto K = static_cast<double>(beam_depth_count(p.max_depth, p.depth_step));
  const double l1 =
      spec.fixed_direction ? std::abs(p.fixed[0]) + std::abs(p.fixed[1]) + std::abs(p.fixed[2]) : std::sqrt(3.0);
  const double cells = std::min(p.max_depth, p.diagonal) * l1 / grid.voxel_size() + 3.0;
  const auto rays = static_cast<double>(spec.rays);
  const auto values = static_cast<double>(grid.active_voxel_count());
  const double shards = std::min(static_cast<double>(kMaxShards), std::ceil(rays / static_cast<double>(kChunk)));
  const double workers = std::min<double>(kMaxShards, thread_count());
  constexpr double kD = sizeof(double);
  PassCost c;
  c.steps = 2.0 * rays * (cells + K) + values;
  // Accumulators (shards and totals), the depths, both curves' three arrays, p_Q and μ̄T_S, and
  // one profile per thread; then the origins' table.
  c.bytes =
      (2.0 * 3.0 * (shards + 1.0) + 1.0 + 2.0 * 3.0 + 2.0 + workers) * K * kD + 2.0 * values * (sizeof(ParticleCell));
  return c;
}

/// The plan of a request that passed every check (check_scatterer).
ScattererPlan checked_plan(const Grid& grid, const ScattererSpec& spec) {
  const ScattererPlan p = plan_of(grid, spec);
  check_pass_cost(fmt::format("scatterer and source rays ({:.4g} of each kind)", static_cast<double>(spec.rays)), grid,
                  scatterer_cost(grid, spec, p));
  return p;
}

}  // namespace

void check_scatterer(const Grid& grid, const ScattererSpec& spec) { (void)checked_plan(grid, spec); }

ScattererCurves measure_scatterer(const Grid& grid, const ScattererSpec& spec, ProgressSink& progress) {
  const ScattererPlan plan = checked_plan(grid, spec);
  const Vec3 fixed = plan.fixed;
  const double h = grid.voxel_size();
  const IndexBox box = grid.active_bbox();
  const auto ext = box.extent();
  const auto o = grid.origin();
  // Origins ∝ C: the active voxels and tiles of positive value with their cumulative weights,
  // in order of position (z, then y, then x of the lower corner), not of the tree: the tree's
  // leaves sit at multiples of 8 in index space, so the same cloth stored at another index
  // origin would list its voxels in another order and draw other particles for the same seed
  // (docs/validate.md "Particle origins in order of position"). Boxes do not overlap, so the
  // order is total and the sort's result does not depend on the threads.
  std::vector<ParticleCell> cells;
  for (auto it = grid.impl().grid->cbeginValueOn(); it; ++it) {
    if (!(*it > 0.0F)) continue;
    ParticleCell c;
    it.getBoundingBox(c.box);
    c.cdf = static_cast<double>(*it) * static_cast<double>(it.getVoxelCount());
    cells.push_back(c);
  }
  if (cells.empty()) fail("scatterer rays: grid '{}' holds no particles (no positive values)", grid.name());
  tbb::parallel_sort(cells.begin(), cells.end(), [](const ParticleCell& a, const ParticleCell& b) {
    const openvdb::Coord& p = a.box.min();
    const openvdb::Coord& q = b.box.min();
    return std::make_tuple(p.z(), p.y(), p.x()) < std::make_tuple(q.z(), q.y(), q.x());
  });
  double run = 0.0;
  for (ParticleCell& c : cells) c.cdf = run += c.cdf;
  const std::vector<double> depths = beam_depth_grid(plan.max_depth, plan.depth_step);
  const std::uint64_t units = (spec.rays + kChunk - 1) / kChunk;
  const std::size_t shards = static_cast<std::size_t>(std::min<std::uint64_t>(kMaxShards, units));
  std::vector<LseAccumulator> s_parts(shards, LseAccumulator(depths.size()));
  std::vector<LseAccumulator> q_parts(shards, LseAccumulator(depths.size()));
  ProgressTask task(progress, "scatterer/source rays", units);
  parallel_units(shards, [&](std::size_t shard) {
    Tracer tracer(grid);
    std::vector<double> tau(depths.size());
    const std::uint64_t begin = shard * units / shards;
    const std::uint64_t end = (shard + 1) * units / shards;
    for (std::uint64_t u = begin; u < end; ++u) {
      Pcg32 rng = stream_for(spec.seed, u);
      const std::uint64_t n = std::min(kChunk, spec.rays - u * kChunk);
      for (std::uint64_t r = 0; r < n; ++r) {
        Vec3 dir = fixed;
        if (!spec.fixed_direction) {
          const double z = 1.0 - 2.0 * rng.uniform();
          const double phi = 2.0 * M_PI * rng.uniform();
          const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
          dir = {s * std::cos(phi), s * std::sin(phi), z};
        }
        // Particle origin: a cell ∝ its weight, then uniform inside it.
        const double pick = rng.uniform() * run;
        const auto idx =
            static_cast<std::size_t>(std::upper_bound(cells.begin(), cells.end(), pick,
                                                      [](double x, const ParticleCell& c) { return x < c.cdf; }) -
                                     cells.begin());
        const auto& b = cells[std::min(idx, cells.size() - 1)].box;
        Ray sray;
        for (int a = 0; a < 3; ++a) {
          const double lo = o[a] + h * b.min()[a];
          const double span = h * static_cast<double>(b.max()[a] - b.min()[a] + 1);
          sray.origin[a] = lo + span * rng.uniform();
        }
        sray.direction = dir;
        Ray qray;
        for (int a = 0; a < 3; ++a)
          qray.origin[a] = o[a] + h * (box.min[a] + static_cast<double>(ext[a]) * rng.uniform());
        qray.direction = dir;
        tau = tracer.optical_depth_profile(sray, depths, spec.scale);
        s_parts[shard].add(tau.data());
        tau = tracer.optical_depth_profile(qray, depths, spec.scale);
        q_parts[shard].add(tau.data());
      }
      task.step();
    }
  });
  LseAccumulator s_total(depths.size());
  LseAccumulator q_total(depths.size());
  for (std::size_t i = 0; i < shards; ++i) {
    s_total.merge(s_parts[i]);
    q_total.merge(q_parts[i]);
  }
  ScattererCurves out;
  for (auto* c : {&out.t_s, &out.t_q}) {
    c->depth = depths;
    c->rays = spec.rays;
    c->distinct_rays = spec.rays;
    c->direction = fixed;
    c->method = spec.fixed_direction ? "fixed direction" : "isotropic directions";
  }
  s_total.finish(out.t_s, s_total.n);
  q_total.finish(out.t_q, q_total.n);
  // μ̄ from the particles' total in the table's order (Grid::sum adds in tree order, whose
  // rounding would differ between index origins).
  out.mean_extinction =
      spec.scale * run / (static_cast<double>(ext[0]) * static_cast<double>(ext[1]) * static_cast<double>(ext[2]));
  const std::size_t K = depths.size();
  out.p_q.assign(K, 0.0);
  out.mu_t_s.assign(K, 0.0);
  for (std::size_t k = 0; k < K; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1;
    const std::size_t b = k + 1 < K ? k + 1 : K - 1;
    if (b > a) out.p_q[k] = -(out.t_q.transmittance(b) - out.t_q.transmittance(a)) / (depths[b] - depths[a]);
    out.mu_t_s[k] = out.mean_extinction * out.t_s.transmittance(k);
  }
  return out;
}

}  // namespace weft::volume
