#include "data_gen/cloth/estimate.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "data_gen/cloth/pattern.h"
#include "data_gen/cloth/yarn.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"

namespace weft::cloth {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kLeafBytes = 512 * 4 + 64 + 96;   // an 8³ float leaf with its mask and node
constexpr double kBinBytes = 32;                   // voxelize.cpp: (leaf, piece id) with the sort's scratch
constexpr double kFiberBytes = 8 + 8 + 4 * 4;      // offset, radius, yarn/ply/fiber ids, kind
constexpr double kVtkPointBytes = 24 + 8;          // vtkPoints (double) and connectivity
constexpr double kVtkCellBytes = 8 + 4 * 4 + 8;    // offset, int arrays, radius
constexpr double kStationBytes = sizeof(Station);  // centreline frames, held while fibres are made

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
  ClothEstimate e;
  double points = 0.0;
  double fibers = 0.0;
  double length = 0.0;
  double voxels = 0.0;
  double leaves = 0.0;
  double bins = 0.0;
  double stations = 0.0;
  for (std::size_t i = 0; i < centerlines.curves.size(); ++i) {
    const YarnParams& y = centerlines.direction[i] == 1 ? spec.weft_yarn : spec.warp_yarn;
    const double L = curve_length(centerlines.curves[i]);
    const double plies = y.ply_count;
    const double st = std::max(1.0, std::ceil(L / y.sample_step)) + 1.0;
    stations += st;
    // Regular fibres wind around their ply (radius ≈ 0.6 ply radius) and the ply around the yarn.
    const double helix = std::sqrt(1.0 + std::pow(2.0 * kPi * y.ply_offset / y.ply_pitch, 2) +
                                   std::pow(2.0 * kPi * 0.6 * y.ply_radius / y.fiber_pitch, 2));
    const double hairs = y.hair_density * L;
    const double hair_points = std::ceil(std::max(y.hair_length_mean, y.sample_step) / y.sample_step) + 1.5;
    points += plies * (y.fiber_count * st + hairs * hair_points);
    fibers += plies * (y.fiber_count + hairs);
    const double fiber_length = plies * (y.fiber_count * L * helix + hairs * y.hair_length_mean);
    length += fiber_length;
    // Voxelizer pieces (≤ 4 voxels long) and the leaves each piece's box touches.
    const double segment = y.sample_step * helix;
    const double per_segment = std::max(1.0, std::ceil(segment / (4.0 * h)));
    const double segments = plies * (y.fiber_count * (st - 1.0) + hairs * (hair_points - 1.0));
    const double piece_width = segment / per_segment / std::sqrt(3.0) + 2.0 * y.fiber_radius;
    bins += segments * per_segment * std::pow(1.0 + piece_width / (8.0 * h), 3);
    // Active voxels: each ply a Boolean model in a disc of its (elliptic) area.
    const double rho = y.ply_radius * y.rho_max * std::sqrt(y.ellipse_n * y.ellipse_b);
    const double a_ply = dilated_area(rho + y.fiber_radius, h);
    const double a_fiber = dilated_area(y.fiber_radius, h);
    voxels += plies * L * a_ply * -std::expm1(-y.fiber_count * helix * a_fiber / a_ply) / (h * h * h);
    voxels += plies * hairs * y.hair_length_mean * a_fiber / (h * h * h);
    // Leaves: the yarn as a tube of its envelope radius in cells of 8h; hairs add half a leaf each.
    const double H = 8.0 * h;
    leaves += L * dilated_area(yarn_envelope_radius(y) + y.fiber_radius, H) / (H * H * H) + 0.5 * plies * hairs;
  }
  e.fiber_length = length;
  e.overflow = !std::isfinite(length);
  bool& o = e.overflow;
  e.fibers = count(fibers, o);
  e.fiber_points = count(points, o);
  e.fiber_bytes = count(points * sizeof(Point3) + fibers * kFiberBytes, o);
  e.active_voxels = count(voxels, o);
  e.leaves = count(std::ceil(leaves), o);
  // Internal nodes: one 16³ node per 128³ voxels touched (32 KiB), bounded by the leaves.
  const double internal = std::min(leaves, std::max(1.0, leaves / 64.0)) * (4096 * 8 + 1024) + 32768 * 8 + 8192;
  e.grid_bytes = count(leaves * kLeafBytes + internal, o);
  const double voxelize = bins * kBinBytes;  // pieces themselves are not stored
  const double vtk = points * kVtkPointBytes + fibers * kVtkCellBytes;
  e.transient_bytes = count(std::max({voxelize, vtk, stations * kStationBytes}), o);
  e.peak_bytes = count(points * sizeof(Point3) + fibers * kFiberBytes + leaves * kLeafBytes + internal +
                           std::max({voxelize, vtk, stations * kStationBytes}),
                       o);
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
  e.fibers = scale(p.fibers);
  e.fiber_points = scale(p.fiber_points);
  e.fiber_bytes = scale(p.fiber_bytes);
  e.active_voxels = scale(p.active_voxels);
  e.leaves = scale(p.leaves);
  e.grid_bytes = scale(p.grid_bytes);
  e.transient_bytes = scale(p.transient_bytes);
  e.peak_bytes = scale(p.peak_bytes);
  return e;
}

std::string describe(const ClothEstimate& e) {
  return fmt::format("{} fibres, {:.4g} mm of fibre, {} points ({}); ~{:.3g} active voxels, grid {}; peak ~{}",
                     e.fibers, e.fiber_length, e.fiber_points, format_bytes(e.fiber_bytes),
                     static_cast<double>(e.active_voxels), format_bytes(e.grid_bytes), format_bytes(e.peak_bytes));
}

void check_budget(const ClothEstimate& e, std::uint64_t budget_bytes, FrontEnd asker, const std::string& subject) {
  const std::uint64_t budget = budget_bytes > 0 ? budget_bytes : default_memory_budget();
  if (e.overflow) {
    // Saturated counts are not figures: say what overflowed instead of printing 2⁶⁴ − 1.
    const Spelling options{"--input-scale, --yarns, --voxel-size", "input_scale=, yarns=, voxel_size="};
    fail(
        "{}: the estimate overflows ({:.3g} mm of fibre; fibres, points or bytes past 2^64): far beyond any "
        "memory (check {})",
        subject, e.fiber_length, options.in(asker));
  }
  if (e.peak_bytes > budget) {
    const Spelling options{"--max-memory; check --input-scale, --yarns, --voxel-size",
                           "max_memory_mb=; check input_scale=, yarns=, voxel_size="};
    fail("{}: estimated {}, over the memory budget of {} ({})", subject, describe(e), format_bytes(budget),
         options.in(asker));
  }
}

}  // namespace weft::cloth
