#include "data_gen/media2d/structure.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Periodic_2_Delaunay_triangulation_2.h>
#include <CGAL/Periodic_2_Delaunay_triangulation_traits_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include "weft/core/error.h"

namespace weft::media2d {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Traits = CGAL::Periodic_2_Delaunay_triangulation_traits_2<Kernel>;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, Traits,
                                                               CGAL::Periodic_2_triangulation_vertex_base_2<Traits>>;
using FaceBase = CGAL::Periodic_2_triangulation_face_base_2<Traits>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using PeriodicDelaunay = CGAL::Periodic_2_Delaunay_triangulation_2<Traits, Tds>;

// Nearest-neighbour distance of every centre, from the edges of the periodic Delaunay
// triangulation; empty when CGAL keeps the 9-sheeted covering (too few or too clustered points).
std::vector<double> delaunay_nearest(const Medium& medium, double& mean_degree) {
  PeriodicDelaunay triangulation(Traits::Iso_rectangle_2(0.0, 0.0, 1.0, 1.0));
  std::vector<Kernel::Point_2> points;
  points.reserve(medium.centers.size());
  for (const auto& c : medium.centers) points.emplace_back(c.x, c.y);
  triangulation.insert(points.begin(), points.end(), true);
  if (!triangulation.is_1_cover() && triangulation.is_triangulation_in_1_sheet()) {
    triangulation.convert_to_1_sheeted_covering();
  }
  if (!triangulation.is_1_cover()) return {};
  // Vertices are labelled with their centre's input index, so the statistics are summed in input
  // order whatever order CGAL keeps its vertices in (a thread-count-dependent last-bit difference
  // in the mean nearest-neighbour distance was seen once under ASan; docs/robustness.md).
  std::map<std::pair<double, double>, std::uint32_t> input_index;
  for (std::size_t i = 0; i < points.size(); ++i)
    input_index.emplace(std::pair{points[i].x(), points[i].y()}, static_cast<std::uint32_t>(i));
  std::uint32_t index = 0;
  for (auto v = triangulation.vertices_begin(); v != triangulation.vertices_end(); ++v) {
    v->info() = input_index.at({v->point().x(), v->point().y()});
    ++index;
  }
  std::vector<double> nearest(points.size(), std::numeric_limits<double>::infinity());
  std::size_t edges = 0;
  for (auto e = triangulation.edges_begin(); e != triangulation.edges_end(); ++e) {
    const auto face = e->first;
    const std::uint32_t a = face->vertex(PeriodicDelaunay::cw(e->second))->info();
    const std::uint32_t b = face->vertex(PeriodicDelaunay::ccw(e->second))->info();
    // The length from the two centres' nearest periodic images, not from CGAL's segment: the
    // segment adds the edge's periodic offset to one end, and which end, and so the rounding,
    // follows CGAL's insertion order, which its spatial sort randomises from a process-wide
    // generator: the last bit of the mean then depended on which realizations a rank had
    // triangulated before. periodic_delta is antisymmetric bit for bit, and a 1-sheeted
    // covering's edges are shorter than half the period, so the nearest image is the edge.
    const Point2 d = periodic_delta(medium.centers[a], medium.centers[b]);
    const double length = std::sqrt(d.x * d.x + d.y * d.y);
    nearest[a] = std::min(nearest[a], length);
    nearest[b] = std::min(nearest[b], length);
    ++edges;
  }
  mean_degree = index > 0 ? 2.0 * static_cast<double>(edges) / static_cast<double>(index) : 0.0;
  // Coincident centres are one vertex: drop the copies that CGAL did not keep.
  std::erase_if(nearest, [](double l) { return std::isinf(l); });
  return nearest;
}

// Ordered periodic pairs with separation in [0, rho_max), binned; cell list of side ≥ rho_max.
std::vector<double> pair_counts(const Medium& medium, double rho_max, std::size_t bins) {
  const std::size_t n = medium.centers.size();
  auto cells = static_cast<std::size_t>(std::clamp(std::floor(1.0 / rho_max), 1.0, 4096.0));
  // With fewer than 3 cells per side the 3×3 neighbourhood would alias: use one cell.
  if (cells < 3) cells = 1;
  std::vector<std::vector<std::uint32_t>> grid(cells * cells);
  const double g = static_cast<double>(cells);
  auto cell_of = [&](double v) { return std::min(cells - 1, static_cast<std::size_t>(v * g)); };
  for (std::size_t i = 0; i < n; ++i) {
    grid[cell_of(medium.centers[i].y) * cells + cell_of(medium.centers[i].x)].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<double> counts(bins, 0.0);
  const double width = rho_max / static_cast<double>(bins);
  const long reach = cells >= 3 ? 1 : 0;
  for (std::size_t cy = 0; cy < cells; ++cy) {
    for (std::size_t cx = 0; cx < cells; ++cx) {
      for (const std::uint32_t i : grid[cy * cells + cx]) {
        for (long dy = -reach; dy <= reach; ++dy) {
          for (long dx = -reach; dx <= reach; ++dx) {
            const auto ny = static_cast<std::size_t>((static_cast<long>(cy + cells) + dy) % static_cast<long>(cells));
            const auto nx = static_cast<std::size_t>((static_cast<long>(cx + cells) + dx) % static_cast<long>(cells));
            for (const std::uint32_t j : grid[ny * cells + nx]) {
              if (j == i) continue;
              const Point2 d = periodic_delta(medium.centers[i], medium.centers[j]);
              const double rho2 = d.x * d.x + d.y * d.y;
              if (rho2 < rho_max * rho_max) {
                counts[std::min(bins - 1, static_cast<std::size_t>(std::sqrt(rho2) / width))] += 1.0;
              }
            }
          }
        }
      }
    }
  }
  return counts;
}

}  // namespace

StructureStats structure_stats(const Medium& medium, std::size_t realization, double g_max, std::size_t g_bins,
                               double nn_max, std::size_t nn_bins) {
  StructureStats s;
  s.realization = realization;
  s.points = medium.centers.size();
  if (s.points < 4) fail("structure statistics: need at least 4 particles, got {}", s.points);
  const double n = static_cast<double>(s.points);
  const double d = 1.0 / std::sqrt(n);

  const std::vector<double> nearest = delaunay_nearest(medium, s.mean_delaunay_degree);
  s.nn_edges.resize(nn_bins + 1);
  s.nn_density.assign(nn_bins, 0.0);
  for (std::size_t k = 0; k <= nn_bins; ++k)
    s.nn_edges[k] = nn_max * static_cast<double>(k) / static_cast<double>(nn_bins);
  if (nearest.empty()) {
    s.note = "CGAL kept the 9-sheeted covering (points too few or too clustered); no nearest-neighbour statistics";
  } else {
    s.delaunay_ok = true;
    double sum = 0.0;
    double sum2 = 0.0;
    std::size_t overlapping = 0;
    const double width = nn_max / static_cast<double>(nn_bins);
    for (const double l : nearest) {
      const double u = l / d;
      sum += u;
      sum2 += u * u;
      if (l < 2.0 * medium.radius) ++overlapping;
      if (u < nn_max) s.nn_density[static_cast<std::size_t>(u / width)] += 1.0;
    }
    const double m = static_cast<double>(nearest.size());
    s.mean_nn = sum / m;
    s.sd_nn = std::sqrt(std::max(0.0, sum2 / m - s.mean_nn * s.mean_nn));
    for (auto& v : s.nn_density) v /= m * width;
    s.max_overlap_fraction = static_cast<double>(overlapping) / m;
  }

  // g(ρ) = ordered pairs in the annulus / (n(n − 1)·annulus area): 1 for a Poisson field.
  const double rho_max = std::min(g_max * d, 0.5);
  const std::vector<double> counts = pair_counts(medium, rho_max, g_bins);
  const double width = rho_max / static_cast<double>(g_bins);
  s.g_centres.resize(g_bins);
  s.g.resize(g_bins);
  for (std::size_t k = 0; k < g_bins; ++k) {
    const double a = width * static_cast<double>(k);
    const double b = a + width;
    const double expected = n * (n - 1.0) * std::numbers::pi * (b * b - a * a);
    s.g_centres[k] = 0.5 * (a + b) / d;
    s.g[k] = counts[k] / expected;
  }
  return s;
}

}  // namespace weft::media2d
