#include "data_gen/media2d/disk_grid.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/floor_div.h"

namespace weft::media2d {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Point2 normalised(Point2 d, const char* what) {
  const double len = std::hypot(d.x, d.y);
  if (!(len > 0.0) || !std::isfinite(len)) fail("{}: ray direction must be a finite non-zero vector", what);
  return {d.x / len, d.y / len};
}

// The ray leaves this image of the excluded disk (its scatterer); other images stay visible.
bool starts_on(Point2 o, Point2 c, double r) {
  const double dx = c.x - o.x;
  const double dy = c.y - o.y;
  return dx * dx + dy * dy <= r * r * (1.0 + 1e-6);
}

}  // namespace

double ray_disk_entry(Point2 o, Point2 d, Point2 c, double r) {
  const double vx = c.x - o.x;
  const double vy = c.y - o.y;
  const double cross = vx * d.y - vy * d.x;
  const double r2 = r * r;
  if (cross * cross >= r2) return kInf;
  if (vx * vx + vy * vy < r2) return 0.0;
  const double b = vx * d.x + vy * d.y;
  const double t = b - std::sqrt(r2 - cross * cross);
  return t >= 0.0 ? t : kInf;
}

DiskGrid::DiskGrid(const Medium& medium, double per_cell) : radius_(medium.radius) {
  const auto count = static_cast<double>(medium.centers.size());
  n_ = static_cast<std::size_t>(std::clamp(std::round(std::sqrt(count / per_cell)), 1.0, 8192.0));
  const auto n = static_cast<std::int64_t>(n_);
  const double g = static_cast<double>(n_);
  start_.assign(n_ * n_ + 1, 0);
  // Two passes (count, fill) over the cells each disk's bounding box touches.
  auto for_cells = [&](const Point2& c, auto&& visit) {
    const auto i0 = static_cast<std::int64_t>(std::floor((c.x - radius_) * g));
    const auto i1 = static_cast<std::int64_t>(std::floor((c.x + radius_) * g));
    const auto j0 = static_cast<std::int64_t>(std::floor((c.y - radius_) * g));
    const auto j1 = static_cast<std::int64_t>(std::floor((c.y + radius_) * g));
    for (std::int64_t j = j0; j <= j1; ++j) {
      for (std::int64_t i = i0; i <= i1; ++i) {
        const std::int64_t wi = i - floor_div(i, n) * n;
        const std::int64_t wj = j - floor_div(j, n) * n;
        // The image of the centre that lies beside wrapped cell (wi, wj).
        const double sx = c.x - static_cast<double>(floor_div(i, n));
        const double sy = c.y - static_cast<double>(floor_div(j, n));
        visit(static_cast<std::size_t>(wj * n + wi), sx, sy);
      }
    }
  };
  for (const auto& c : medium.centers) {
    for_cells(c, [&](std::size_t cell, double, double) { ++start_[cell + 1]; });
  }
  for (std::size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
  entries_.resize(start_.back());
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t idx = 0; idx < medium.centers.size(); ++idx) {
    for_cells(medium.centers[idx], [&](std::size_t cell, double sx, double sy) {
      entries_[fill[cell]++] = Entry{sx, sy, idx};
    });
  }
}

Hit DiskGrid::first_hit(Point2 origin, Point2 direction, double t_max, std::size_t exclude) const {
  const Point2 d = normalised(direction, "disk grid");
  const auto n = static_cast<std::int64_t>(n_);
  const double g = static_cast<double>(n_);
  const double h = 1.0 / g;
  auto cell_x = static_cast<std::int64_t>(std::floor(origin.x * g));
  auto cell_y = static_cast<std::int64_t>(std::floor(origin.y * g));
  const std::int64_t step_x = d.x > 0.0 ? 1 : -1;
  const std::int64_t step_y = d.y > 0.0 ? 1 : -1;
  // Amanatides–Woo: parametric distance to the next vertical / horizontal cell wall.
  double next_x = kInf;
  double next_y = kInf;
  double delta_x = kInf;
  double delta_y = kInf;
  if (d.x != 0.0) {
    const double wall = static_cast<double>(cell_x + (d.x > 0.0 ? 1 : 0)) * h;
    next_x = (wall - origin.x) / d.x;
    delta_x = h / std::abs(d.x);
  }
  if (d.y != 0.0) {
    const double wall = static_cast<double>(cell_y + (d.y > 0.0 ? 1 : 0)) * h;
    next_y = (wall - origin.y) / d.y;
    delta_y = h / std::abs(d.y);
  }
  // A ray along an axis (one component exactly 0) runs along one row or column of the torus:
  // p(t + 1) = p(t) + (±1, 0) or (0, ±1), an image of the same point, so a disk image entered at
  // t > 1 has its neighbouring image entered at t − 1 ≥ 0. Its first hit, if any, is at t ≤ 1
  // (docs/sim2d.md "Rays"); the 2r beyond absorb rounding of the entry distances. Without this
  // bound a ray in an empty row walked every cell up to t_max, however far.
  const double limit = d.x == 0.0 || d.y == 0.0 ? std::min(t_max, 1.0 + 2.0 * radius_) : t_max;
  Hit best;
  for (;;) {
    const std::int64_t ox = floor_div(cell_x, n);
    const std::int64_t oy = floor_div(cell_y, n);
    const std::size_t cell = static_cast<std::size_t>((cell_y - oy * n) * n + (cell_x - ox * n));
    const double shift_x = static_cast<double>(ox);
    const double shift_y = static_cast<double>(oy);
    for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
      const Entry& e = entries_[k];
      const Point2 c{e.x + shift_x, e.y + shift_y};
      if (e.disk == exclude && starts_on(origin, c, radius_)) continue;
      const double t = ray_disk_entry(origin, d, c, radius_);
      if (t < best.t) best = Hit{t, e.disk};
    }
    const double leave = std::min(next_x, next_y);
    // Every disk overlapping this cell is listed in it, so a hit before the cell's exit is final.
    if (best.t <= leave || leave > limit) break;
    if (next_x < next_y) {
      cell_x += step_x;
      next_x += delta_x;
    } else {
      cell_y += step_y;
      next_y += delta_y;
    }
  }
  if (best.t > t_max) return Hit{};
  return best;
}

bool DiskGrid::inside_any(Point2 p, std::size_t exclude) const {
  const auto n = static_cast<std::int64_t>(n_);
  const double g = static_cast<double>(n_);
  const auto cx = static_cast<std::int64_t>(std::floor(p.x * g));
  const auto cy = static_cast<std::int64_t>(std::floor(p.y * g));
  const std::int64_t ox = floor_div(cx, n);
  const std::int64_t oy = floor_div(cy, n);
  const std::size_t cell = static_cast<std::size_t>((cy - oy * n) * n + (cx - ox * n));
  for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
    const Entry& e = entries_[k];
    if (e.disk == exclude) continue;
    const double dx = e.x + static_cast<double>(ox) - p.x;
    const double dy = e.y + static_cast<double>(oy) - p.y;
    if (dx * dx + dy * dy < radius_ * radius_) return true;
  }
  return false;
}

Hit brute_force_first_hit(const Medium& medium, Point2 origin, Point2 direction, double t_max, std::size_t exclude) {
  const Point2 d = normalised(direction, "brute force");
  const Point2 end{origin.x + t_max * d.x, origin.y + t_max * d.y};
  const double r = medium.radius;
  Hit best;
  for (std::size_t idx = 0; idx < medium.centers.size(); ++idx) {
    const Point2 c = medium.centers[idx];
    const auto kx0 = static_cast<std::int64_t>(std::floor(std::min(origin.x, end.x) - r - c.x));
    const auto kx1 = static_cast<std::int64_t>(std::ceil(std::max(origin.x, end.x) + r - c.x));
    const auto ky0 = static_cast<std::int64_t>(std::floor(std::min(origin.y, end.y) - r - c.y));
    const auto ky1 = static_cast<std::int64_t>(std::ceil(std::max(origin.y, end.y) + r - c.y));
    for (std::int64_t kx = kx0; kx <= kx1; ++kx) {
      for (std::int64_t ky = ky0; ky <= ky1; ++ky) {
        const Point2 image{c.x + static_cast<double>(kx), c.y + static_cast<double>(ky)};
        if (idx == exclude && starts_on(origin, image, r)) continue;
        const double t = ray_disk_entry(origin, d, image, r);
        if (t < best.t) best = Hit{t, idx};
      }
    }
  }
  if (best.t > t_max) return Hit{};
  return best;
}

}  // namespace weft::media2d
