#pragma once
/// @file
/// @brief Majorant grids for delta and ratio tracking through a voxel grid, their traversal
/// and the point lookups the trackers make (the role of pbrt-v4's `MajorantGrid` and
/// `DDAMajorantIterator`, media.h).
///
/// The majorant grid is a coarse sparse grid of cells of 8³ voxels (a leaf node's size),
/// anchored at the lower corner of the active voxels rather than at the index lattice's
/// multiples of 8 (docs/render.md §5 "Majorant cells anchored to the cloth": the same cloth stored at
/// another index origin gets the same cells, so the same tracking and the same image), each
/// holding the maximum value over its voxels and their neighbours. It is traversed by the same Amanatides–Woo kernel as
/// the density grid (dda_impl.h), so empty space is skipped a tree node at a time on the coarse tree as well.

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "weft/core/rng.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// A non-owning reference to a callable (no allocation, one indirect call per use): the
/// per-segment callback of hot loops, where std::function would allocate per flight.
template <typename Signature>
class FunctionRef;

template <typename R, typename... Args>
class FunctionRef<R(Args...)> {
 public:
  template <typename F, typename = std::enable_if_t<!std::is_same_v<std::decay_t<F>, FunctionRef>>>
  FunctionRef(F&& f) noexcept  // NOLINT(google-explicit-constructor): used like a lambda
      : object_(const_cast<void*>(static_cast<const void*>(&f))),
        call_([](void* o, Args... args) -> R { return (*static_cast<std::remove_reference_t<F>*>(o))(args...); }) {}
  R operator()(Args... args) const { return call_(object_, args...); }

 private:
  void* object_;
  R (*call_)(void*, Args...);
};

/// @brief Per-block upper bounds of a grid's values (read-only, shared between threads).
///
/// Cell K covers the voxels a + 8K … a + 8K + 7 per axis, a the lower corner of the active
/// voxels (of every channel's, block_lattice.h); its value is the maximum
/// over those voxels and every voxel within one voxel of them (dilation), so a point lookup that
/// rounds across a cell face still finds value ≤ majorant. Active tiles give their value to
/// every cell they touch. Values are the grid's own (unscaled): for μ = scale·value the
/// majorant is scale·cell.
///
/// Several channels (grids of one voxel size and origin, e.g. the three per-axis extinctions of
/// a direction-dependent medium, docs/render.md §6d) share one majorant grid: each cell holds
/// the maximum over every channel, i.e. of the per-voxel maximum, which bounds any combination
/// Σ_c w_c·value_c with w_c ≥ 0 and Σ_c w_c ≤ 1.
class MajorantGrid {
 public:
  static constexpr int kBlock = 8;  ///< voxels per cell side: the leaf node's DIM

  explicit MajorantGrid(const Grid& grid);
  /// One majorant grid over every channel (at least one; throws weft::Error naming the grids
  /// when their voxel sizes or origins differ).
  explicit MajorantGrid(const std::vector<const Grid*>& channels);
  ~MajorantGrid();
  MajorantGrid(MajorantGrid&&) noexcept;
  MajorantGrid& operator=(MajorantGrid&&) noexcept;

  /// The coarse grid (voxel size 8h; its index 0 starts at the active voxels' lower corner, so
  /// its origin is the fine grid's moved there).
  [[nodiscard]] const Grid& cells() const { return *cells_; }
  /// The largest value of the grid (the global majorant over scale).
  [[nodiscard]] double max_value() const { return max_value_; }
  /// Number of cells with a majorant > 0.
  [[nodiscard]] std::uint64_t active_cells() const;

 private:
  std::unique_ptr<Grid> cells_;
  double max_value_ = 0.0;
};

/// @brief Russian roulette of a shadow estimate that only falls along its segment (pbrt-v4's
/// ratio tracking): once the estimate is below kBelow it ends (0) with probability kStop, else
/// is divided by 1 − kStop. Unbiased, and a shadow ray through a dense yarn stops after a few
/// steps instead of crossing the whole cloth (docs/render.md §6). The one rule of every tracked
/// or walked shadow: ratio tracking's product, and estimates e^{−τ} of an exact walk, held as
/// the survivals' weight in log space (no exponential per step).
class ShadowRoulette {
 public:
  static constexpr double kBelow = 0.05;
  static constexpr double kStop = 0.75;

  /// Ratio tracking's running product tr: false when the roulette ended it (tr = 0).
  static bool keep(double& tr, Pcg32& rng) {
    if (!(tr < kBelow)) return true;
    if (rng.uniform() < kStop) {
      tr = 0.0;
      return false;
    }
    tr /= 1.0 - kStop;
    return true;
  }
  /// An exact walk that has reached depth τ (estimate e^{−τ}·the survivals' weight): false
  /// when the roulette ended it.
  bool keep_depth(double tau, Pcg32& rng) {
    if (!(tau - log_weight_ > kLogBelow)) return true;
    if (rng.uniform() < kStop) return false;
    log_weight_ += kLogSurvive;
    return true;
  }
  /// The estimate of a walk that kept going to depth τ.
  [[nodiscard]] double estimate(double tau) const { return std::exp(log_weight_ - tau); }

 private:
  static inline const double kLogBelow = -std::log(kBelow);
  static inline const double kLogSurvive = -std::log(1.0 - kStop);
  double log_weight_ = 0.0;
};

/// A real collision found by delta tracking.
struct TrackedCollision {
  bool collided = false;
  double t = 0.0;  ///< world distance of the collision (valid when collided)
};

/// Work counters of a tracker (benchmarks: voxels crossed per second).
struct TrackerCounters {
  std::uint64_t cells = 0;    ///< majorant cells (or tree nodes) visited
  std::uint64_t lookups = 0;  ///< tentative collisions: density point lookups
};

/// @brief Delta and ratio tracking through one grid against its MajorantGrid, for one thread
/// (holds OpenVDB accessors; cheap to make). μ(x) = scale·value(voxel containing x); with
/// several channels and per-ray weights w (the overloads taking them), μ(x) = scale·Σ_c w_c
/// value_c(x), the weights ≥ 0 with Σ w_c ≤ 1 so that the channels' common majorant bounds it.
class MajorantTracker {
 public:
  MajorantTracker(const Grid& grid, const MajorantGrid& majorants);
  /// Channels as given to the MajorantGrid (same grids, same order).
  MajorantTracker(const std::vector<const Grid*>& channels, const MajorantGrid& majorants);
  ~MajorantTracker();
  MajorantTracker(MajorantTracker&&) noexcept;
  MajorantTracker& operator=(MajorantTracker&&) noexcept;
  MajorantTracker(const MajorantTracker&) = delete;
  MajorantTracker& operator=(const MajorantTracker&) = delete;

  /// Calls visit(t_a, t_b, majorant value) for the majorant cells the ray crosses over
  /// [t0, t1] in order, skipping empty tree nodes (segments of value 0 are still reported, so
  /// the segments tile the clipped interval); stops when visit returns false. The direction
  /// need not be unit; t is world distance along the normalised direction.
  void walk(const Ray& ray, double t0, double t1, FunctionRef<bool(double, double, double)> visit);

  /// Value of the voxel containing world point x (index ⌊(x − origin)/h⌋; 0 where inactive).
  [[nodiscard]] double value_at(const std::array<double, 3>& x);

  /// Delta tracking (Woodcock): tentative collisions at rate scale·majorant per cell,
  /// accepted with probability μ(x)/majorant; the first accepted one over [t0, t1), or none.
  /// Exact sampling of the exponential free flight e^{−∫μ} (pbrt-v4 §14.2.1).
  [[nodiscard]] TrackedCollision delta_track(const Ray& ray, double t0, double t1, double scale, Pcg32& rng);

  /// Ratio tracking (Novák et al. 2014): the product over tentative collisions of
  /// (1 − μ(x)/majorant), an unbiased estimate of e^{−∫_{t0}^{t1} μ}; below 0.05 it is
  /// continued by Russian roulette (stop with probability 0.75, else divide by 0.25).
  [[nodiscard]] double ratio_track(const Ray& ray, double t0, double t1, double scale, Pcg32& rng);

  /// The same two over the weighted sum of the channels, one weight per channel (see above).
  [[nodiscard]] TrackedCollision delta_track(const Ray& ray, double t0, double t1, double scale,
                                             const std::vector<double>& weights, Pcg32& rng);
  [[nodiscard]] double ratio_track(const Ray& ray, double t0, double t1, double scale,
                                   const std::vector<double>& weights, Pcg32& rng);

  [[nodiscard]] const TrackerCounters& counters() const { return counters_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  TrackerCounters counters_;
};

/// Where a march to a given optical depth ended.
struct DepthHit {
  bool reached = false;  ///< τ reached `tau_star` inside [t0, t1]
  double t = 0.0;        ///< world distance where it was reached (t1 when not)
  double tau = 0.0;      ///< optical depth accumulated up to t
};

/// @brief Exact optical-depth flights for laws other than the exponential: march the voxels
/// (one DDA, dda.h) until ∫ scale·value dt reaches τ*, for one thread.
class DepthTracker {
 public:
  explicit DepthTracker(const Grid& grid);
  ~DepthTracker();
  DepthTracker(DepthTracker&&) noexcept;
  DepthTracker& operator=(DepthTracker&&) noexcept;
  DepthTracker(const DepthTracker&) = delete;
  DepthTracker& operator=(const DepthTracker&) = delete;

  /// The first t in [t0, t1] where τ(t) = ∫_{t0}^{t} scale·value reaches tau_star (linear
  /// inside a voxel, so exact), or t1 and τ(t1) when it does not.
  [[nodiscard]] DepthHit march_to(const Ray& ray, double t0, double t1, double scale, double tau_star);
  /// τ over [t0, t1].
  [[nodiscard]] double optical_depth(const Ray& ray, double t0, double t1, double scale);
  /// e^{−τ} over [t0, t1], the walk ended early by ShadowRoulette once it is small (an
  /// unbiased estimate; exact while it stays above ShadowRoulette::kBelow).
  [[nodiscard]] double transmittance(const Ray& ray, double t0, double t1, double scale, Pcg32& rng);

  [[nodiscard]] const TrackerCounters& counters() const { return counters_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  TrackerCounters counters_;
};

}  // namespace weft::volume
