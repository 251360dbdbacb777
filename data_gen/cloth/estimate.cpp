#include "data_gen/cloth/estimate.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "data_gen/cloth/pattern.h"
#include "data_gen/cloth/yarn.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/volume/pass_budget.h"

namespace weft::cloth {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kLeafBytes = 512 * 4 + 64 + 96;  // an 8³ float leaf with its mask and node
constexpr double kBinBytes = 32;                  // voxelize.cpp: (leaf, piece id) with the sort's scratch
constexpr double kFiberBytes = 8 + 8 + 4 * 4;     // offset, radius, yarn/ply/fiber ids, kind
constexpr double kVtkPointBytes = 24 + 8;         // vtkPoints (double) and connectivity
constexpr double kVtkCellBytes = 8 + 4 * 4 + 8;   // offset, int arrays, radius

// Mean area a disc of radius r covers in a lattice of cubes of edge h, per unit length of an
// axis in random orientation: πr² + (mean perimeter 1.5πh)·r + (mean projected area 1.5h²).
double dilated_area(double r, double h) { return kPi * r * r + 1.5 * kPi * h * r + 1.5 * h * h; }

// Saturating conversion: an absurd input (a scale off by 10⁶) must give a huge estimate, not UB;
// past 64 bits (or NaN, from ∞ − ∞) the estimate is marked as overflowed.
std::uint64_t count(double x, bool& overflow) {
  if (!(x < 1.8e19)) {
    overflow = true;
    return ~0ULL;
  }
  return static_cast<std::uint64_t>(std::max(0.0, x));
}

}  // namespace

ClothEstimate estimate_cloth(const ClothSpec& spec, const CurveSet& centerlines) {
  const double h = spec.voxel_size;
  const double H = 8.0 * h;  // a leaf's edge
  ClothEstimate e;
  double points = 0.0;
  double fibers = 0.0;
  double length = 0.0;
  double voxels = 0.0;
  double leaves = 0.0;
  double bins = 0.0;
  double plan = 0.0;
  double loops = 0.0;
  double loop_bytes = 0.0;
  double steps = 0.0;
  double loop_steps = 0.0;
  double loop_leaves = 0.0;  // along loop excursions
  double hair_leaves = 0.0;
  double hair_points = 0.0;
  double hairs = 0.0;
  for (std::size_t i = 0; i < centerlines.curves.size(); ++i) {
    const YarnParams& y = centerlines.direction[i] == 1 ? spec.weft_yarn : spec.warp_yarn;
    const double L = curve_length(centerlines.curves[i]);
    const double plies = y.ply_count;
    const double regular = plies * y.fiber_count;
    const YarnCost cost = yarn_cost(y, L);
    const double st = cost.stations;
    // Regular fibres wind around their ply (radius ≈ 0.6 ply radius) and the ply around the yarn.
    const double helix = std::sqrt(1.0 + std::pow(2.0 * kPi * y.ply_offset / y.ply_pitch, 2) +
                                   std::pow(2.0 * kPi * 0.6 * y.ply_radius / y.fiber_pitch, 2));
    // Flyaways (yarn.cpp), in ply radii rp along the larger semi-axis. A hair runs its axial
    // length, rises by its span and turns about the ply centre at about its mid radius, each
    // chord of that turn no longer than the diameter it spans.
    const double rp = y.ply_radius * std::max(y.ellipse_n, y.ellipse_b);
    const double hair_axial = cost.hair_length;
    const double hair_segments = std::max(1.0, std::ceil(hair_axial / y.sample_step));
    const double rise = mean_of_floored_normal(0.0, y.hair_span_mean, y.hair_span_sd);
    const double turn = mean_of_floored_normal(0.0, y.hair_angle_span_mean, y.hair_angle_span_sd) +
                        mean_of_floored_normal(0.0, -y.hair_angle_span_mean, y.hair_angle_span_sd);  // E|turn|
    const double arc = std::min(turn * (y.rho_max + 0.5 * rise) * rp, hair_segments * 2.0 * (y.rho_max + rise) * rp);
    const double hair = std::hypot(hair_axial, rise * rp, arc);
    // A loop takes its fibre from about 0.6 ply radius out to the loop radius and back over one
    // migration period, turning 2π·period/fiber_pitch about the ply centre meanwhile at about half
    // that extra radius: extra length ≈ ΔR·rp·(2 + π·period/fiber_pitch). Loops are Poisson along
    // each fibre (loop_coverage c over a point) and overlapping ones make one excursion: 1 − e^(−c)
    // excursions per fibre and period, one per loop while they are sparse (c ≪ 1), one per
    // period once they cover the fibre.
    const double reach = mean_of_floored_normal(y.rho_max, y.loop_radius_mean, y.loop_radius_sd);
    const double per_excursion = (2.0 + kPi * y.migration_period / y.fiber_pitch) * rp;
    const double loop_extra = std::max(0.0, reach - 0.6) * per_excursion;
    const double excursions = regular * L / y.migration_period * -std::expm1(-loop_coverage(y));
    const double flyaways = cost.hairs * hair + excursions * loop_extra;
    points += cost.points;
    fibers += regular + cost.hairs;
    length += regular * L * helix + flyaways;
    plan += cost.plan_bytes;
    loops += cost.loops;
    loop_bytes += cost.loop_bytes;
    steps += cost.steps;
    loop_steps += cost.loop_steps;
    hairs += cost.hairs;
    hair_points += cost.points - regular * st;
    e.loop_density = std::max(e.loop_density, y.loop_density);
    e.loop_coverage = std::max(e.loop_coverage, loop_coverage(y));
    // Voxelizer pieces (≤ 4 voxels long) and the leaves each piece's box touches.
    const double segment = y.sample_step * helix;
    const double per_segment = std::max(1.0, std::ceil(segment / (4.0 * h)));
    const double piece_width = segment / per_segment / std::sqrt(3.0) + 2.0 * y.fiber_radius;
    bins += regular * (st - 1.0) * per_segment * std::pow(1.0 + piece_width / H, 3);
    const double fly_pieces =
        cost.hairs * std::max(hair_segments, hair / (4.0 * h)) + excursions * loop_extra / (4.0 * h);
    bins += fly_pieces * std::pow(1.0 + (4.0 * h / std::sqrt(3.0) + 2.0 * y.fiber_radius) / H, 3);
    // Active voxels: each ply a Boolean model in a disc of its (elliptic) area; flyaways outside.
    const double rho = y.ply_radius * y.rho_max * std::sqrt(y.ellipse_n * y.ellipse_b);
    const double a_ply = dilated_area(rho + y.fiber_radius, h);
    const double a_fiber = dilated_area(y.fiber_radius, h);
    voxels += plies * L * a_ply * -std::expm1(-y.fiber_count * helix * a_fiber / a_ply) / (h * h * h);
    voxels += flyaways * a_fiber / (h * h * h);
    // Leaves: the yarn as a tube of its envelope radius in cells of 8h. A flyaway adds half a leaf
    // and the cells its path crosses off the yarn: a path of length ℓ crosses 1.5ℓ/H cells of edge
    // H (|dx| + |dy| + |dz| averages 1.5 over directions). For a hair, what its rise and turn add
    // to its axial length; for a loop, its path beyond the envelope; the loops at most the tube out
    // to their radius (mean + 2 sd) around the envelope's.
    const auto path_leaves = [H](double l) { return 0.5 + 1.5 * l / H; };
    const double envelope = yarn_envelope_radius(y) + y.fiber_radius;
    const double tube = L * dilated_area(envelope, H) / (H * H * H);
    leaves += tube;
    hair_leaves += cost.hairs * path_leaves(hair - hair_axial);
    const double loop_tube =
        L *
            dilated_area(
                y.ply_offset + std::max(reach, y.loop_radius_mean + 2.0 * y.loop_radius_sd) * rp + y.fiber_radius, H) /
            (H * H * H) -
        tube;
    loop_leaves +=
        std::min(excursions * path_leaves(std::max(0.0, reach - y.rho_max) * per_excursion), std::max(0.0, loop_tube));
  }
  leaves += hair_leaves + loop_leaves;
  e.fiber_length = length;
  e.overflow = !std::isfinite(length);
  bool& o = e.overflow;
  e.fibers = count(fibers, o);
  e.fiber_points = count(points, o);
  e.fiber_bytes = count(points * sizeof(Point3) + fibers * kFiberBytes, o);
  e.active_voxels = count(voxels, o);
  e.leaves = count(std::ceil(leaves), o);
  e.loops = count(loops, o);
  e.loop_bytes = count(loop_bytes, o);
  e.loop_reach_bytes = count(loop_leaves * kLeafBytes, o);
  e.hair_bytes = count(hair_points * sizeof(Point3) + hairs * kFiberBytes + hair_leaves * kLeafBytes, o);
  e.plan_bytes = count(plan, o);
  e.steps = steps;
  e.loop_steps = loop_steps;
  o = o || !(steps < 1.8e19);
  // Internal nodes: one 16³ node per 128³ voxels touched (32 KiB), bounded by the leaves.
  const double internal = std::min(leaves, std::max(1.0, leaves / 64.0)) * (4096 * 8 + 1024) + 32768 * 8 + 8192;
  e.grid_bytes = count(leaves * kLeafBytes + internal, o);
  const double voxelize = bins * kBinBytes;  // pieces themselves are not stored
  const double vtk = points * kVtkPointBytes + fibers * kVtkCellBytes;
  // The plan (stations, flyaways) lives while the points are made, the bins while they are
  // voxelized, the VTK copy while fibers.vtp is written: one at a time.
  const double transient = std::max({voxelize, vtk, plan});
  e.transient_bytes = count(transient, o);
  e.voxelizer_bytes = count(voxelize, o);
  e.vtk_bytes = count(vtk, o);
  e.peak_bytes = count(points * sizeof(Point3) + fibers * kFiberBytes + leaves * kLeafBytes + internal + transient, o);
  return e;
}

ClothEstimate without_grid(ClothEstimate e) {
  e.active_voxels = 0;
  e.leaves = 0;
  e.grid_bytes = 0;
  e.loop_reach_bytes = 0;  // grid leaves along the loops' paths
  e.voxelizer_bytes = 0;
  e.transient_bytes = std::max(e.vtk_bytes, e.plan_bytes);
  // Saturated counts stay saturated (overflow is kept, and check_budget says so).
  e.peak_bytes = e.fiber_bytes > ~0ULL - e.transient_bytes ? ~0ULL : e.fiber_bytes + e.transient_bytes;
  return e;
}

ClothEstimate estimate_cloth(const ClothSpec& spec) {
  if (spec.pattern == "import") fail("estimate_cloth: an imported cloth is estimated on its curves");
  constexpr int kProbe = 60;  // lcm of the pattern repeats 2, 3, 4, 5
  if (spec.warp_count <= kProbe && spec.weft_count <= kProbe) return estimate_cloth(spec, cloth_centerlines(spec));
  ClothSpec probe = spec;
  probe.warp_count = std::min(spec.warp_count, kProbe);
  probe.weft_count = std::min(spec.weft_count, kProbe);
  const ClothEstimate p = estimate_cloth(probe, cloth_centerlines(probe));
  const double f = static_cast<double>(spec.warp_count) * spec.weft_count / (probe.warp_count * probe.weft_count);
  ClothEstimate e;
  e.overflow = p.overflow || !std::isfinite(p.fiber_length * f);
  const auto scale = [&](std::uint64_t v) { return count(static_cast<double>(v) * f, e.overflow); };
  e.fiber_length = p.fiber_length * f;
  e.loops = scale(p.loops);
  e.loop_bytes = scale(p.loop_bytes);
  e.loop_reach_bytes = scale(p.loop_reach_bytes);
  e.hair_bytes = scale(p.hair_bytes);
  e.plan_bytes = scale(p.plan_bytes);
  e.steps = p.steps * f;
  e.loop_steps = p.loop_steps * f;
  e.loop_density = p.loop_density;
  e.loop_coverage = p.loop_coverage;
  e.fibers = scale(p.fibers);
  e.fiber_points = scale(p.fiber_points);
  e.fiber_bytes = scale(p.fiber_bytes);
  e.active_voxels = scale(p.active_voxels);
  e.leaves = scale(p.leaves);
  e.grid_bytes = scale(p.grid_bytes);
  e.transient_bytes = scale(p.transient_bytes);
  e.voxelizer_bytes = scale(p.voxelizer_bytes);
  e.vtk_bytes = scale(p.vtk_bytes);
  e.peak_bytes = scale(p.peak_bytes);
  return e;
}

std::string describe(const ClothEstimate& e) { return describe(e, format_bytes(e.peak_bytes)); }

std::string describe(const ClothEstimate& e, const std::string& peak) {
  // A build without a grid (without_grid) says none.
  const std::string grid = e.grid_bytes == 0 && e.active_voxels == 0
                               ? std::string("no grid")
                               : fmt::format("~{:.3g} active voxels, grid {}", static_cast<double>(e.active_voxels),
                                             format_bytes(e.grid_bytes));
  return fmt::format("{} fibres, {:.4g} mm of fibre, {} points ({}), {} loop flyaways; {}; peak ~{}", e.fibers,
                     e.fiber_length, e.fiber_points, format_bytes(e.fiber_bytes), e.loops, grid, peak);
}

namespace {

// What to change, in the asker's words: the flyaway parameter behind more than half of `total`
// (bytes or steps) when one is, else the options that scale a whole cloth (`otherwise`).
std::string advice(const ClothEstimate& e, double total, double loops, double reach, double hairs, FrontEnd asker,
                   const Spelling& otherwise) {
  const std::string set = asker == FrontEnd::cli ? "--set " : "";
  if (2.0 * loops > total) {
    return fmt::format(
        "{} loop flyaways from {}loop_density={:.3g} per mm of ply, {:.3g} over each fibre point (loop_density x "
        "migration_period / fiber_count): lower it",
        e.loops == ~0ULL ? std::string("more than 2^64") : fmt::format("{:.3g}", static_cast<double>(e.loops)), set,
        e.loop_density, e.loop_coverage);
  }
  if (2.0 * reach > total)
    return fmt::format("the loop flyaways' reach, {}loop_radius_mean and loop_radius_sd (in ply radii): lower them",
                       set);
  if (2.0 * hairs > total) {
    return fmt::format(
        "the hair flyaways, {}hair_density, hair_length_mean, hair_span_mean and hair_angle_span_mean: lower them",
        set);
  }
  return otherwise.in(asker);
}

}  // namespace

void check_budget(const ClothEstimate& e, std::uint64_t budget_bytes, FrontEnd asker, const std::string& subject,
                  const std::string& config) {
  // A value read from a config is changed there (or overridden by the option): both are named.
  const std::string in_config =
      config.empty() ? "" : fmt::format(" or the keys input_scale, warp_count, weft_count, voxel_size of {}", config);
  const std::uint64_t budget = budget_bytes > 0 ? budget_bytes : default_memory_budget();
  const auto peak = static_cast<double>(e.peak_bytes);
  const auto bytes_advice = [&](const Spelling& otherwise) {
    return advice(e, peak, static_cast<double>(e.loop_bytes), static_cast<double>(e.loop_reach_bytes),
                  static_cast<double>(e.hair_bytes), asker, otherwise);
  };
  if (e.overflow) {
    // Saturated counts are not figures: say what overflowed instead of printing 2⁶⁴ − 1.
    const Spelling options{"check --input-scale, --yarns, --voxel-size" + in_config,
                           "check input_scale=, yarns=, voxel_size=" + in_config};
    // Loops are drawn per mm of fibre, so a fibre length past the range of numbers saturates
    // their count too: the loops are named only when the fibres themselves fit (their length
    // finite, their points counted), i.e. when loop_density is what overflowed.
    const bool fibres_fit = std::isfinite(e.fiber_length) && e.fiber_points != ~0ULL;
    const std::string figures = std::isfinite(e.fiber_length)
                                    ? fmt::format("{:.3g} mm of fibre, {:.3g} steps", e.fiber_length, e.steps)
                                    : std::string("a fibre length past the range of numbers");
    fail("{}: the estimate overflows ({}; fibres, points or bytes past 2^64): far beyond any memory ({})", subject,
         figures,
         !fibres_fit                                        ? options.in(asker)
         : !std::isfinite(e.loop_steps) || e.loops == ~0ULL ? advice(e, 0.0, 1.0, 0.0, 0.0, asker, options)
                                                            : bytes_advice(options));
  }
  if (e.peak_bytes > budget) {
    const Spelling options{"--max-memory; check --input-scale, --yarns, --voxel-size" + in_config,
                           "max_memory_mb=; check input_scale=, yarns=, voxel_size=" + in_config};
    const auto [peak, limit] = format_bytes_apart(e.peak_bytes, budget);
    fail("{}: estimated {}, over the memory budget of {} ({})", subject, describe(e, peak), limit,
         bytes_advice(options));
  }
  // Work, as every pass over a grid is bounded (volume/pass_budget.h): a step here (a point made,
  // a loop blended into it) is about as cheap as a voxel read there (docs/cloth.md "Estimate
  // before spending" gives the measured rate).
  if (!(e.steps <= volume::kMaxPassSteps)) {
    const Spelling options{"check --input-scale, --yarns and the yarns' sample_step, fiber_count" + in_config,
                           "check input_scale=, yarns= and the yarns' sample_step, fiber_count" + in_config};
    fail(
        "{}: making the fibres would take {:.3g} steps (points made, loop flyaways blended into them), over the limit "
        "of {:.3g} ({})",
        subject, e.steps, volume::kMaxPassSteps, advice(e, e.steps, e.loop_steps, 0.0, 0.0, asker, options));
  }
}

}  // namespace weft::cloth
