#pragma once
/// @file
/// @brief Ray–disk intersection over the periodic unit square with a uniform-grid 2D DDA.
///
/// Each disk is listed in every cell its bounding box touches, with its centre shifted to the
/// periodic image nearest that cell; a ray walks unwrapped cells (Amanatides–Woo 1987), maps each
/// to its wrapped cell plus an integer image offset, and so travels any number of domain lengths.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "data_gen/media2d/medium.h"

namespace weft::media2d {

inline constexpr std::size_t kNoDisk = std::numeric_limits<std::size_t>::max();

/// @brief The first disk along a ray.
struct Hit {
  double t = std::numeric_limits<double>::infinity();  ///< distance to the disk's boundary (0 if inside)
  std::size_t disk = kNoDisk;
  [[nodiscard]] bool found() const { return disk != kNoDisk; }
};

/// @brief Entry distance of the ray o + t·d (|d| = 1) into the disk (c, r): 0 if o is inside,
/// +∞ if missed or behind. The perpendicular offset is a cross product, so tiny radii far from
/// the origin do not cancel.
[[nodiscard]] double ray_disk_entry(Point2 o, Point2 d, Point2 c, double r);

/// @brief Uniform grid over the periodic unit square holding a medium's disks.
class DiskGrid {
 public:
  /// @brief Builds the grid with about `per_cell` disks per cell.
  explicit DiskGrid(const Medium& medium, double per_cell = 2.0);

  /// @brief First disk hit by o + t·d for t ∈ [0, t_max], skipping the image of disk `exclude` the ray starts on
  /// (a scatterer emitting it); its other periodic images can still be hit.
  /// `d` need not be normalised; distances are along the normalised direction. A ray along an
  /// axis repeats its path after one domain length, so its walk stops there whatever `t_max`.
  [[nodiscard]] Hit first_hit(Point2 origin, Point2 direction, double t_max, std::size_t exclude = kNoDisk) const;

  /// @brief True if `p` lies strictly inside any disk other than `exclude`.
  [[nodiscard]] bool inside_any(Point2 p, std::size_t exclude = kNoDisk) const;

  [[nodiscard]] std::size_t cells_per_side() const { return n_; }
  [[nodiscard]] double radius() const { return radius_; }

 private:
  struct Entry {
    double x;
    double y;
    std::size_t disk;
  };
  std::size_t n_ = 1;
  double radius_ = 0.0;
  std::vector<std::uint32_t> start_;  // CSR offsets, n_² + 1
  std::vector<Entry> entries_;
};

/// @brief Reference answer for tests: every disk, every periodic image the ray can reach.
[[nodiscard]] Hit brute_force_first_hit(const Medium& medium, Point2 origin, Point2 direction, double t_max,
                                        std::size_t exclude = kNoDisk);

}  // namespace weft::media2d
