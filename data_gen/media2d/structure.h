#pragma once
/// @file
/// @brief Structure statistics of one realization: what η did to the particle positions.
///
/// Nearest-neighbour distances come from CGAL's periodic 2D Delaunay triangulation of the centres
/// (every point's nearest neighbour is one of its Delaunay neighbours); the pair-correlation
/// g(ρ) counts periodic pairs in annuli with a cell list. Distances are in units of the mean
/// inter-particle distance d = 1/√n, where a Poisson field has mean nearest-neighbour distance ½.

#include <cstddef>
#include <string>
#include <vector>

#include "data_gen/media2d/medium.h"

namespace weft::media2d {

struct StructureStats {
  std::size_t realization = 0;
  std::size_t points = 0;
  bool delaunay_ok = false;  ///< false when CGAL could not build a 1-sheeted periodic triangulation
  std::string note;
  double mean_nn = 0.0;  ///< mean nearest-neighbour distance / d (Poisson: 0.5)
  double sd_nn = 0.0;
  double mean_delaunay_degree = 0.0;  ///< 6 for any periodic triangulation (Euler), a consistency check
  std::vector<double> nn_edges;       ///< histogram edges in d
  std::vector<double> nn_density;     ///< pdf of nearest-neighbour distance / d
  std::vector<double> g_centres;      ///< ρ / d
  std::vector<double> g;              ///< pair correlation (Poisson: 1)
  double max_overlap_fraction = 0.0;  ///< fraction of disks whose nearest neighbour is closer than 2r
};

/// @brief Computes the statistics; `g_max` and `nn_max` are in units of d.
[[nodiscard]] StructureStats structure_stats(const Medium& medium, std::size_t realization = 0, double g_max = 3.0,
                                             std::size_t g_bins = 30, double nn_max = 2.0, std::size_t nn_bins = 40);

}  // namespace weft::media2d
