#pragma once
/// @file
/// @brief The sums behind a beam's T(t) when every ray is a sample: Σ T_i(t_k) and Σ T_i(t_k)²
/// over the rays, kept per shard (a fixed number of them, so the totals are the same bytes for
/// any thread count) and turned into the mean T with its standard error. The fibre beam and the
/// fields' prediction of a beam (render/local_gamma_beam.h) share it; the voxel beam keeps its
/// log-sum-exp accumulators (T far below 1e−300).

#include <cstdint>
#include <string>
#include <vector>

#include "weft/volume/beam.h"

namespace weft::volume {

struct CurveSums {
  std::vector<double> s1;  ///< Σ over rays of T_i(t_k)
  std::vector<double> s2;  ///< Σ over rays of T_i(t_k)²
  std::uint64_t n = 0;     ///< rays

  explicit CurveSums(std::size_t depths = 0) : s1(depths, 0.0), s2(depths, 0.0) {}
  /// One ray's T_i(t_k) = e^{log_t[k]}.
  void add_log(const std::vector<double>& log_t);
  /// Adds another part's sums (same depths) to these.
  void merge(const CurveSums& other);
};

/// The parts' total (in the parts' order) as a curve on `depths`: log of the mean T, and its
/// standard error relative to the mean; log T = −∞ (standard error 0) where no ray got through.
/// Throws weft::Error, "`what`: no ray entered …", when the parts hold no ray.
[[nodiscard]] TransmittanceCurve curve_of_sums(const std::vector<CurveSums>& parts, const std::vector<double>& depths,
                                               const std::array<double, 3>& direction, std::string method,
                                               const std::string& what);

}  // namespace weft::volume
