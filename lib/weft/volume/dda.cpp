#include "weft/volume/dda.h"

#include <algorithm>
#include <cmath>

#include "weft/volume/dda_impl.h"
#include "weft/volume/grid_openvdb.h"
#include "weft/volume/voxel_walk.h"

namespace weft::volume {

namespace detail {
void fail_bad_ray(const Ray& ray, double tmin, double tmax) {
  if (std::isnan(tmin) || std::isnan(tmax)) fail("ray: t range [{}, {}] is not a number", tmin, tmax);
  const auto& o = ray.origin;
  const auto& d = ray.direction;
  for (std::size_t a = 0; a < 3; ++a) {
    if (!std::isfinite(o[a])) fail("ray: origin component {} is {}", a, o[a]);
    if (!std::isfinite(d[a])) fail("ray: direction component {} is {}", a, d[a]);
  }
  fail("ray: direction ({}, {}, {}) has no length", d[0], d[1], d[2]);
}
}  // namespace detail

struct Tracer::Impl {
  openvdb::FloatGrid::ConstPtr grid;
  detail::Accessor acc;
  detail::CellBox box;
  detail::CellMap map;
  detail::CellWalk walk;  // the pull-style march of start/next
  explicit Impl(openvdb::FloatGrid::ConstPtr g)
      : grid(std::move(g)), acc(grid->getConstAccessor()), box(detail::active_cell_box(*grid)), map(*grid) {}
};

Tracer::Tracer(const Grid& grid) : impl_(std::make_unique<Impl>(grid.impl().grid)) {}
Tracer::~Tracer() = default;
Tracer::Tracer(Tracer&&) noexcept = default;
Tracer& Tracer::operator=(Tracer&&) noexcept = default;

namespace {
void require_range(double tmin, double tmax) {
  if (std::isnan(tmin) || std::isnan(tmax)) detail::fail_bad_ray(Ray{}, tmin, tmax);
}
}  // namespace

void Tracer::march(const Ray& ray, double tmin, double tmax, const SegmentVisitor& visit) {
  require_range(tmin, tmax);
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  detail::march_cells(impl_->acc, r, impl_->box, tmin, tmax,
                      [&](double t0, double t1, float v, const std::int64_t* cell, int size) {
                        Segment s;
                        s.t0 = t0;
                        s.t1 = t1;
                        s.value = v;
                        s.voxel = {static_cast<int>(cell[0]), static_cast<int>(cell[1]), static_cast<int>(cell[2])};
                        s.size = size;
                        return visit(s);
                      });
}

void Tracer::start(const Ray& ray, double tmin, double tmax) {
  require_range(tmin, tmax);
  impl_->walk.done = true;
  (void)impl_->walk.start(detail::to_cell_ray(impl_->map, ray), impl_->box, tmin, tmax);
}

bool Tracer::next(Segment& s) {
  detail::CellStep c;
  if (!impl_->walk.next(impl_->acc, c)) return false;
  s.t0 = c.t0;
  s.t1 = c.t1;
  s.value = c.value;
  s.voxel = {static_cast<int>(c.lo[0]), static_cast<int>(c.lo[1]), static_cast<int>(c.lo[2])};
  s.size = c.size;
  return true;
}

double Tracer::optical_depth(const Ray& ray, double tmin, double tmax, double scale) {
  require_range(tmin, tmax);
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  double tau = 0.0;
  detail::march_cells(impl_->acc, r, impl_->box, tmin, tmax,
                      [&](double t0, double t1, float v, const std::int64_t*, int) {
                        tau += (t1 - t0) * static_cast<double>(v);
                        return true;
                      });
  return tau * scale;
}

std::vector<double> Tracer::optical_depth_profile(const Ray& ray, const std::vector<double>& depths, double scale) {
  for (std::size_t k = 0; k < depths.size(); ++k) {
    if (!(depths[k] >= 0.0) || !std::isfinite(depths[k]) || (k > 0 && depths[k] < depths[k - 1])) {
      fail("optical depth profile: depths must be finite, >= 0 and increasing (entry {} is {})", k, depths[k]);
    }
  }
  std::vector<double> tau(depths.size(), 0.0);
  if (depths.empty()) return tau;
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  std::size_t k = 0;
  double acc = 0.0;
  detail::march_cells(impl_->acc, r, impl_->box, 0.0, depths.back(),
                      [&](double t0, double t1, float v, const std::int64_t*, int) {
                        const double mu = static_cast<double>(v);
                        // Depths before this segment were already filled; τ is linear inside it.
                        while (k < depths.size() && depths[k] <= t1) {
                          tau[k] = acc + mu * std::max(0.0, depths[k] - t0);
                          ++k;
                        }
                        acc += mu * (t1 - t0);
                        return k < depths.size();
                      });
  for (; k < depths.size(); ++k) tau[k] = acc;
  for (double& x : tau) x *= scale;
  return tau;
}

BoxHit Tracer::intersect_active_box(const Ray& ray, double tmin) const {
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  BoxHit hit;
  double t0 = tmin;
  double t1 = std::numeric_limits<double>::infinity();
  if (detail::clip(r, impl_->box, t0, t1)) {
    hit.hit = true;
    hit.t_enter = t0;
    hit.t_exit = t1;
  }
  return hit;
}

void march(const Grid& grid, const Ray& ray, double tmin, double tmax, const SegmentVisitor& visit) {
  Tracer(grid).march(ray, tmin, tmax, visit);
}

double optical_depth(const Grid& grid, const Ray& ray, double tmin, double tmax, double scale) {
  return Tracer(grid).optical_depth(ray, tmin, tmax, scale);
}

std::vector<double> optical_depth_profile(const Grid& grid, const Ray& ray, const std::vector<double>& depths,
                                          double scale) {
  return Tracer(grid).optical_depth_profile(ray, depths, scale);
}

DenseWalk::DenseWalk(const detail::IndexMap& map, const IndexBox& box) : map_(map), empty_(box.empty()) {
  if (empty_) return;
  for (std::size_t a = 0; a < 3; ++a) {
    box_lo_[a] = box.min[a];
    box_hi_[a] = std::int64_t{box.max[a]} + 1;
    lo_[a] = static_cast<double>(box_lo_[a]);
    hi_[a] = static_cast<double>(box_hi_[a]);
  }
  stride_[2] = 1;
  stride_[1] = box_hi_[2] - box_lo_[2];
  stride_[0] = stride_[1] * (box_hi_[1] - box_lo_[1]);
}

bool dense_walk_map(const Grid& grid, detail::IndexMap& map) {
  const detail::CellMap cell_map(*grid.impl().grid);
  if (!cell_map.scale_translate) return false;
  map = cell_map.index;
  return true;
}

BoxHit intersect_active_box(const Grid& grid, const Ray& ray, double tmin) {
  return Tracer(grid).intersect_active_box(ray, tmin);
}

}  // namespace weft::volume
