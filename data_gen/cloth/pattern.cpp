#include "data_gen/cloth/pattern.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "data_gen/cloth/yarn.h"
#include "weft/core/error.h"
#include "weft/curves/curve_io.h"

namespace weft::cloth {
namespace {

int positive_mod(int a, int n) { return ((a % n) + n) % n; }
int floor_div(int a, int n) { return (a - positive_mod(a, n)) / n; }

// Points per unit of the smaller spacing: enough that the polyline's chord error is far below a
// fibre radius (the yarn generator resamples it at sample_step anyway).
constexpr int kPointsPerSpacing = 32;

// C¹ periodic interpolation through values at the crossings u = k + ½ (u in spacings).
template <typename Value>
double eased(double u, Value value_at) {
  const double c = u - 0.5;
  const double k = std::floor(c);
  const double t = c - k;
  const double a = value_at(static_cast<int>(k));
  const double b = value_at(static_cast<int>(k) + 1);
  return a + (b - a) * 0.5 * (1.0 - std::cos(std::numbers::pi * t));
}

}  // namespace

bool warp_over(const std::string& pattern, int i, int j) {
  if (pattern == "plain") return positive_mod(i + j, 2) == 0;
  if (pattern == "twill21") return positive_mod(i + j, 3) < 2;
  if (pattern == "twill22") return positive_mod(i + j, 4) < 2;
  if (pattern == "twill31") return positive_mod(i + j, 4) < 3;
  // 5-harness warp-faced satin with move number 2: one interlacing per warp per repeat, never
  // adjacent to the neighbour's (2 is coprime to 5 and not ±1).
  if (pattern == "satin5") return positive_mod(i + 2 * j, 5) != 0;
  // 2×2 basket: plain weave of yarn pairs.
  if (pattern == "basket") return positive_mod(floor_div(i, 2) + floor_div(j, 2), 2) == 0;
  fail("pattern: '{}' is not a woven pattern", pattern);
}

int pattern_repeat(const std::string& pattern) {
  if (pattern == "plain") return 2;
  if (pattern == "twill21") return 3;
  if (pattern == "twill22" || pattern == "twill31" || pattern == "basket") return 4;
  if (pattern == "satin5") return 5;
  fail("pattern: '{}' is not a woven pattern", pattern);
}

double warp_height(const ClothSpec& spec, int j, double x) {
  return eased(x / spec.weft_spacing, [&](int i) { return warp_over(spec.pattern, i, j) ? spec.crimp : -spec.crimp; });
}

double weft_height(const ClothSpec& spec, int i, double y) {
  return eased(y / spec.warp_spacing, [&](int j) { return warp_over(spec.pattern, i, j) ? -spec.crimp : spec.crimp; });
}

CurveSet woven_centerlines(const ClothSpec& spec) {
  CurveSet out;
  const double width = spec.weft_count * spec.weft_spacing;   // extent along x
  const double height = spec.warp_count * spec.warp_spacing;  // extent along y
  const auto nx = static_cast<int>(spec.weft_count) * kPointsPerSpacing;
  const auto ny = static_cast<int>(spec.warp_count) * kPointsPerSpacing;
  for (int j = 0; j < spec.warp_count; ++j) {
    Curve c;
    const double y = (j + 0.5) * spec.warp_spacing;
    for (int k = 0; k <= nx; ++k) {
      const double x = width * k / nx;
      c.points.push_back({x, y, warp_height(spec, j, x)});
    }
    out.curves.push_back(std::move(c));
    out.direction.push_back(0);
  }
  for (int i = 0; i < spec.weft_count; ++i) {
    Curve c;
    const double x = (i + 0.5) * spec.weft_spacing;
    for (int k = 0; k <= ny; ++k) {
      const double y = height * k / ny;
      c.points.push_back({x, y, weft_height(spec, i, y)});
    }
    out.curves.push_back(std::move(c));
    out.direction.push_back(1);
  }
  return out;
}

CurveSet knit_centerlines(const ClothSpec& spec) {
  CurveSet out;
  const double W = spec.weft_spacing;
  const double H = spec.warp_spacing;
  const double loop_height = 1.5 * H;
  const double D = spec.crimp;
  constexpr double a = 0.05;
  constexpr int per_stitch = 64;
  const int n = spec.weft_count * per_stitch;
  for (int r = 0; r < spec.warp_count; ++r) {
    Curve c;
    for (int k = 0; k <= n; ++k) {
      const double t = 2.0 * std::numbers::pi * k / per_stitch;
      c.points.push_back({W * (t / (2.0 * std::numbers::pi) + a * std::sin(2.0 * t)),
                          r * H + 0.5 * loop_height * (1.0 - std::cos(t)), D * std::cos(t)});
    }
    out.curves.push_back(std::move(c));
    out.direction.push_back(0);
  }
  return out;
}

CurveSet cloth_centerlines(const ClothSpec& spec) {
  if (spec.pattern == "stockinette") return knit_centerlines(spec);
  if (spec.pattern == "import") {
    CurveSet set;
    set.curves = curves::read_curves(spec.input);
    if (set.curves.empty()) fail("{}: the file holds no curves", spec.input);
    for (std::size_t i = 0; i < set.curves.size(); ++i) {
      if (!(curve_length(set.curves[i]) > 0.0))
        fail("{}: curve {} has no length (fewer than two distinct points)", spec.input, i);
    }
    for (std::size_t i = 0; i < set.curves.size(); ++i) {
      for (auto& p : set.curves[i].points) {
        for (double& v : p) {
          v *= spec.input_scale;
          if (!std::isfinite(v))
            fail("{}: input_scale {} takes curve {} beyond the range of numbers (a coordinate of {})", spec.input,
                 spec.input_scale, i, v);
        }
      }
      // Past the voxelizer's index range (spec.h kMaxVoxelIndex) the curve cannot be voxelized:
      // said with the file and the point, before the estimate turns its length into an overflow.
      const double reach = static_cast<double>(kMaxVoxelIndex) * spec.voxel_size;
      for (std::size_t k = 0; k < set.curves[i].points.size(); ++k) {
        const auto& p = set.curves[i].points[k];
        if (std::abs(p[0]) < reach && std::abs(p[1]) < reach && std::abs(p[2]) < reach) continue;
        fail(
            "{}: curve {} point {} at input_scale {} lies at ({:.3g}, {:.3g}, {:.3g}) mm, past the voxel index range "
            "+-{} at voxel_size {} mm (+-{:.3g} mm): check the file's coordinates, input_scale or voxel_size",
            spec.input, i, k, spec.input_scale, p[0], p[1], p[2], kMaxVoxelIndex, spec.voxel_size, reach);
      }
      // Imported yarns take the warp's parameters (direction 0). Said here, with the file and the
      // scale, not later by a yarn that cannot name either.
      if (const auto why = centerline_problem(set.curves[i], spec.warp_yarn.sample_step); !why.empty())
        fail("{}: curve {} at input_scale {} {}", spec.input, i, spec.input_scale, why);
    }
    // The voxel's upper bound, as for a woven cloth (spec.cpp check_cloth_extent): below the
    // longest side of the curves' box, yarn surfaces included.
    std::array<double, 3> lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::max()};
    std::array<double, 3> hi{-lo[0], -lo[1], -lo[2]};
    for (const auto& c : set.curves) {
      for (const auto& p : c.points) {
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
      }
    }
    const double longest =
        std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}) + 2.0 * yarn_envelope_radius(spec.warp_yarn);
    require_voxel_within(fmt::format("the curves of {} at input_scale {}", spec.input, spec.input_scale), longest,
                         spec.voxel_size);
    set.direction.assign(set.curves.size(), 0);
    return set;
  }
  return woven_centerlines(spec);
}

}  // namespace weft::cloth
