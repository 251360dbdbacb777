#include "weft/volume/beam.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string_view>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/parse_number.h"
#include "weft/volume/beam_accumulate_impl.h"
#include "weft/volume/beam_profiles_impl.h"
#include "weft/volume/columns.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/lattice.h"
#include "weft/volume/pass_budget.h"

namespace weft::volume {
namespace {

using detail::kMaxShards;
using detail::Lattice;
using detail::LseAccumulator;
using detail::stream_columns;
using detail::TauBlock;
using detail::trace_rays;

Lattice make_lattice(const Grid& grid, const BeamSpec& spec) {
  return make_beam_lattice(active_world_box(grid), grid.voxel_size(), spec);
}

}  // namespace

std::vector<double> beam_depths(const Grid& grid, const BeamSpec& spec) {
  if (grid.active_voxel_count() == 0) fail("beam: grid '{}' has no active voxels", grid.name());
  return make_lattice(grid, spec).depths;
}

namespace {

void check_spec(const Grid& grid, const BeamSpec& spec) {
  require_positive("beam: scale (sigma)", spec.scale);
  if (spec.rays_per_column < 1) fail("beam: rays per column must be >= 1, got {}", spec.rays_per_column);
  if (spec.column_stride < 1 || spec.column_stride > 4096) {
    fail("beam: column stride must be in 1..4096, got {}", spec.column_stride);
  }
  if (spec.depth_step != 0.0) require_positive("beam: depth step", spec.depth_step);
  // The first active value, not a count of them all (a parallel pass over every leaf).
  if (!grid.impl().grid->tree().cbeginValueOn()) fail("beam: grid '{}' has no active voxels", grid.name());
  (void)unit_direction(spec.direction, "beam");
  if (spec.method == BeamMethod::streaming && beam_axis(spec.direction) < 0) {
    fail("beam: the streaming method needs an axis direction, got {}", direction_label(spec.direction));
  }
}

BeamMethod resolved(BeamMethod method, int axis) {
  if (method != BeamMethod::automatic) return method;
  return axis >= 0 ? BeamMethod::streaming : BeamMethod::per_ray;
}

BeamCost beam_cost(const Grid& grid, const BeamSpec& spec) {
  const Lattice L = make_beam_lattice(active_world_box(grid), grid.voxel_size(), spec, false);
  const auto K = static_cast<double>(L.depth_count);
  const double workers = std::min<double>(kMaxShards, thread_count());
  constexpr double kD = sizeof(double);
  BeamCost c;
  // Each shard's three sums per depth, their total, the depths and the curve (three per depth).
  c.bytes = (3.0 * kMaxShards + 3.0 + 1.0 + 3.0) * K * kD;
  if (resolved(spec.method, L.axis) == BeamMethod::streaming) {
    const IndexBox box = grid.active_bbox();
    const auto e = box.extent();
    const auto depth = static_cast<double>(e[L.axis]);
    const PassCost columns = column_pass_cost(box, L.axis);
    c.rays = columns.steps / depth;
    // Every column is read whole and profiled at every depth (stream_columns).
    c.steps = c.rays * (depth + K);
    // Per thread: a patch's 64 columns of floats, their 64 profiles and one column's boundaries.
    c.bytes += columns.bytes + workers * (64.0 * depth * sizeof(float) + 64.0 * K * kD + (depth + 1.0) * kD);
  } else {
    const auto s = static_cast<double>(L.stride);
    const double cells = std::ceil(static_cast<double>(L.na) / s) * std::ceil(static_cast<double>(L.nb) / s);
    c.rays = cells * L.per_cell;
    c.steps = c.rays * (L.cells_crossed() + K);
    c.bytes += workers * K * kD;  // one profile per thread
  }
  return c;
}

/// The whole check of a beam request: its spec, then its cost against the budgets.
void check_beam(const Grid& grid, const BeamSpec& spec, double extra_bytes = 0.0) {
  check_spec(grid, spec);
  BeamCost c = beam_cost(grid, spec);
  const std::string what = fmt::format("beam {} ({:.4g} rays)", direction_label(spec.direction), c.rays);
  check_pass_cost(what, grid, {c.steps, c.bytes + extra_bytes});
}

template <typename BlockConsumer, typename RayConsumer, typename SparseConsumer>
void run_beam(const Grid& grid, const BeamSpec& spec, const Lattice& L, ProgressSink& progress,
              BlockConsumer&& consume_block, RayConsumer&& consume, SparseConsumer&& consume_sparse,
              std::string& method_name) {
  const BeamMethod method = resolved(spec.method, L.axis);
  method_name = to_string(method);
  if (method == BeamMethod::streaming) {
    stream_columns(grid, L, spec.scale, progress, consume_block, consume_sparse);
  } else {
    trace_rays(grid, L, spec.scale, method == BeamMethod::openvdb_dda, progress, consume);
  }
}

}  // namespace

std::string to_string(BeamMethod method) {
  switch (method) {
    case BeamMethod::automatic:
      return "auto";
    case BeamMethod::streaming:
      return "streaming";
    case BeamMethod::per_ray:
      return "per-ray";
    case BeamMethod::openvdb_dda:
      return "openvdb";
  }
  return "?";
}

BeamMethod parse_beam_method(const std::string& text) {
  if (text == "auto") return BeamMethod::automatic;
  if (text == "streaming") return BeamMethod::streaming;
  if (text == "per-ray") return BeamMethod::per_ray;
  if (text == "openvdb") return BeamMethod::openvdb_dda;
  fail("beam method '{}' is not one of auto, streaming, per-ray, openvdb", text);
}

double TransmittanceCurve::transmittance(std::size_t k) const { return std::exp(log_t.at(k)); }

std::array<double, 3> parse_direction(const std::string& text) {
  // Blanks around the whole and around each component are dropped, as for every number option
  // (docs/robustness.md): "1, 0, 0" is 1,0,0.
  const auto trimmed = [](std::string_view v) {
    const auto b = v.find_first_not_of(" \t");
    return b == std::string_view::npos ? std::string() : std::string(v.substr(b, v.find_last_not_of(" \t") - b + 1));
  };
  std::string s = trimmed(text);
  double sign = 1.0;
  if (!s.empty() && (s[0] == '+' || s[0] == '-') && s.size() == 2) {
    sign = s[0] == '-' ? -1.0 : 1.0;
    s = s.substr(1);
  }
  if (s == "x" || s == "X") return {sign, 0.0, 0.0};
  if (s == "y" || s == "Y") return {0.0, sign, 0.0};
  if (s == "z" || s == "Z") return {0.0, 0.0, sign};
  std::array<double, 3> d{};
  // getline yields no empty last field: "1,0,0," would read as three numbers.
  if (!s.empty() && s.back() == ',')
    fail("direction '{}': expected x, y, z (optionally signed) or three numbers dx,dy,dz", text);
  std::istringstream in(s);
  std::string part;
  int n = 0;
  while (std::getline(in, part, ',')) {
    if (n >= 3) fail("direction '{}': expected x, y, z (optionally signed) or three numbers dx,dy,dz", text);
    part = trimmed(part);
    const std::optional<double> v = parse_number(part);
    if (!v) fail("direction '{}': '{}' is not a number", text, part);
    d[static_cast<std::size_t>(n)] = *v;
    ++n;
  }
  if (n != 3) fail("direction '{}': expected x, y, z (optionally signed) or three numbers dx,dy,dz", text);
  (void)unit_direction(d, fmt::format("direction '{}'", text).c_str());
  return d;
}

int beam_axis(const std::array<double, 3>& d) {
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (d[a] != 0.0) {
      if (axis >= 0) return -1;
      axis = a;
    }
  }
  return axis;
}

std::string direction_label(const std::array<double, 3>& d) {
  const int a = beam_axis(d);
  if (a >= 0) return fmt::format("{}{}", d[a] < 0.0 ? "-" : "+", "xyz"[a]);
  const auto u = unit_direction(d, "beam");
  return fmt::format("({:.4g}, {:.4g}, {:.4g})", u[0], u[1], u[2]);
}

BeamCost estimate_beam(const Grid& grid, const BeamSpec& spec) {
  check_spec(grid, spec);
  return beam_cost(grid, spec);
}

TransmittanceCurve measure_beam(const Grid& grid, const BeamSpec& spec, ProgressSink& progress) {
  check_beam(grid, spec);
  const Lattice L = make_lattice(grid, spec);
  const std::size_t shards = kMaxShards;
  std::vector<LseAccumulator> parts(shards, LseAccumulator(L.depths.size()));
  std::vector<std::pair<std::vector<double>, std::vector<double>>> scratch(shards);  // one per shard: no sharing
  std::vector<LseAccumulator::SparseScratch> sparse_scratch(shards);
  TransmittanceCurve curve;
  run_beam(
      grid, spec, L, progress,
      [&](std::size_t shard, const TauBlock& block) {
        parts[shard].add_block(block, scratch[shard].first, scratch[shard].second);
      },
      [&](std::size_t shard, std::uint64_t, const double* tau) { parts[shard].add(tau); },
      [&](std::size_t shard, const SparseColumnTile& tile, bool reverse, double mu_h) {
        parts[shard].add_sparse(tile, reverse, mu_h, sparse_scratch[shard]);
      },
      curve.method);
  LseAccumulator total(L.depths.size());
  for (const auto& p : parts) total.merge(p);
  curve.depth = L.depths;
  curve.direction = L.d;
  // Rays of one axis column cross the same voxels: they are one sample, counted once.
  const auto per_cell = static_cast<std::uint64_t>(L.per_cell);
  const bool streamed = curve.method == "streaming";
  curve.rays = streamed ? total.n * per_cell : total.n;
  const std::uint64_t independent = (L.axis >= 0 && !streamed) ? total.n / per_cell : total.n;
  curve.distinct_rays = independent;
  total.finish(curve, independent);
  L.require_full_chord_rays(total.n, "beam " + direction_label(L.d));
  if (total.n == 0) fail("beam {}: no ray entered the grid", direction_label(L.d));
  return curve;
}

BeamDepths beam_optical_depths(const Grid& grid, const BeamSpec& spec) {
  check_spec(grid, spec);
  const BeamCost cost = beam_cost(grid, spec);
  // Every ray's whole profile is returned (the rows of the rays that miss the box included).
  if (cost.rays > 4'000'000) fail("beam optical depths: {:.4g} rays is too many to return", cost.rays);
  const auto depths =
      static_cast<double>(make_beam_lattice(active_world_box(grid), grid.voxel_size(), spec, false).depth_count);
  check_beam(grid, spec, cost.rays * depths * sizeof(double));
  const Lattice L = make_lattice(grid, spec);
  BeamDepths out;
  out.depth = L.depths;
  const std::uint64_t count =
      static_cast<std::uint64_t>(L.na) * static_cast<std::uint64_t>(L.nb) *
      static_cast<std::uint64_t>(resolved(spec.method, L.axis) == BeamMethod::streaming ? 1 : L.per_cell);
  out.tau.assign(count, {});
  std::string method;
  const std::size_t K = L.depths.size();
  run_beam(
      grid, spec, L, null_progress(),
      [&](std::size_t, const TauBlock& block) {
        for (std::size_t c = 0; c < block.cols; ++c) {
          auto& row = out.tau[block.ray[c]];
          row.resize(K);
          for (std::size_t k = 0; k < K; ++k) row[k] = block.tau[k * block.stride + c];
        }
      },
      [&](std::size_t, std::uint64_t ray, const double* tau) { out.tau[ray].assign(tau, tau + K); }, nullptr, method);
  // Rays of a general direction that miss the box leave empty rows.
  std::erase_if(out.tau, [](const std::vector<double>& row) { return row.empty(); });
  return out;
}

}  // namespace weft::volume
