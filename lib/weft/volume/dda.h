#pragma once
/// @file
/// @brief Exact ray traversal of a voxel grid (Amanatides & Woo 1987) and optical depth.
///
/// Voxel values are piecewise constant: voxel (i, j, k) covers index space [i−½, i+½)³
/// (OpenVDB's cell-centred convention; in world space [origin + h·i, origin + h·(i+1)) per axis,
/// see Grid::origin()). A ray's optical depth is then an exact sum over the voxels it crosses of
/// (segment length × μ), μ = σ·C for concentration grids (docs/architecture.md §6, "ground truth").
///
/// A point on a face between two voxels belongs to the voxel on the upper side (half-open
/// intervals), so a ray running exactly along a face, edge or corner line sees every voxel of
/// one column exactly once. Direction components that are exactly 0 (or −0.0) are handled
/// without dividing by them. Empty space is skipped a node at a time using the tree's
/// hierarchy (tiles of 8, 128 or 4096 voxels); active tiles are traversed as one segment.

#include <array>
#include <functional>
#include <memory>
#include <vector>

#include "weft/volume/grid.h"

namespace weft::volume {

/// A ray in world space: points origin + t·direction. `direction` need not be unit: the march
/// normalises it, and every `t` below is a world distance from `origin`.
struct Ray {
  std::array<double, 3> origin{0.0, 0.0, 0.0};
  std::array<double, 3> direction{0.0, 0.0, 1.0};
};

/// One piece of a ray inside one constant-valued cell: a voxel (size 1) or a tile of
/// size³ voxels whose lowest-corner voxel is `voxel`.
struct Segment {
  double t0 = 0.0;     ///< world distance where the ray enters the cell
  double t1 = 0.0;     ///< world distance where it leaves (> t0)
  float value = 0.0f;  ///< the cell's value; 0 for inactive voxels and empty space
  std::array<int, 3> voxel{0, 0, 0};
  int size = 1;
};

/// Receives segments in order of increasing t; returns false to stop the march.
using SegmentVisitor = std::function<bool(const Segment&)>;

/// Where a ray enters and leaves the grid's active bounding box (world distances, clipped to
/// t ≥ tmin); `hit` false when it misses.
struct BoxHit {
  bool hit = false;
  double t_enter = 0.0;
  double t_exit = 0.0;
};

/// Traverses one grid many times: caches the active bounding box and a value accessor.
/// Not thread-safe: use one Tracer per thread (they are cheap). The free functions below build
/// a temporary Tracer per call.
class Tracer {
 public:
  explicit Tracer(const Grid& grid);
  ~Tracer();
  Tracer(Tracer&&) noexcept;
  Tracer& operator=(Tracer&&) noexcept;
  Tracer(const Tracer&) = delete;
  Tracer& operator=(const Tracer&) = delete;

  /// The segments of `ray` over [tmin, tmax] through a callback (std::function: for tools and
  /// tests; hot loops use start/next or, inside volume/, the templated kernel of dda_impl.h).
  void march(const Ray& ray, double tmin, double tmax, const SegmentVisitor& visit);
  /// The same march pulled one segment at a time, without a callback or type erasure: start()
  /// clips the ray (throws weft::Error for a bad ray or range, as march does), then each next()
  /// fills `s` with the following segment and returns false once the march has ended. One walk
  /// at a time per Tracer; starting again abandons the previous one.
  void start(const Ray& ray, double tmin, double tmax);
  [[nodiscard]] bool next(Segment& s);
  [[nodiscard]] double optical_depth(const Ray& ray, double tmin, double tmax, double scale = 1.0);
  [[nodiscard]] std::vector<double> optical_depth_profile(const Ray& ray, const std::vector<double>& depths,
                                                          double scale = 1.0);
  [[nodiscard]] BoxHit intersect_active_box(const Ray& ray, double tmin = 0.0) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Marches `ray` over [tmin, tmax] (world distances) through the grid's active bounding box and
/// calls `visit` for each segment, including empty ones (value 0) so that segments tile the
/// clipped interval without gaps. Rays that miss the box produce no calls. Throws weft::Error
/// for a zero, NaN or infinite direction or origin.
void march(const Grid& grid, const Ray& ray, double tmin, double tmax, const SegmentVisitor& visit);

/// ∫ μ dt over [tmin, tmax] with μ = scale × value (scale = σ for concentration grids,
/// 1 for extinction grids). Exact for piecewise-constant voxels.
[[nodiscard]] double optical_depth(const Grid& grid, const Ray& ray, double tmin, double tmax, double scale = 1.0);

/// Cumulative optical depth τ(t_k) = ∫_0^{t_k} μ dt at increasing world distances
/// `depths` (t measured from the ray origin, all ≥ 0). Exact: τ is piecewise linear.
[[nodiscard]] std::vector<double> optical_depth_profile(const Grid& grid, const Ray& ray,
                                                        const std::vector<double>& depths, double scale = 1.0);

[[nodiscard]] BoxHit intersect_active_box(const Grid& grid, const Ray& ray, double tmin = 0.0);

}  // namespace weft::volume
