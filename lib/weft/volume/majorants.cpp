#include "weft/volume/majorants.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <openvdb/openvdb.h>

#include "weft/core/error.h"
#include "weft/volume/block_lattice.h"
#include "weft/volume/dda_impl.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {

namespace {

static_assert(MajorantGrid::kBlock == 8 && openvdb::FloatTree::LeafNodeType::DIM == 8,
              "majorant cells are the size of the tree's leaves");

/// Raises cell c of the coarse grid to at least v (activating it).
void raise(openvdb::FloatGrid::Accessor& acc, const openvdb::Coord& c, float v) {
  float current = 0.0F;
  const bool on = acc.probeValue(c, current);
  if (!on || v > current) acc.setValue(c, on ? std::max(current, v) : v);
}

/// The cell holding fine voxel c.
openvdb::Coord cell_of(const BlockLattice& cells, const openvdb::Coord& c) {
  return {static_cast<openvdb::Int32>(cells.block_of(0, c.x())), static_cast<openvdb::Int32>(cells.block_of(1, c.y())),
          static_cast<openvdb::Int32>(cells.block_of(2, c.z()))};
}

/// Raises every cell that voxels [lo, hi] (inclusive) dilated by one voxel touch.
void raise_box(openvdb::FloatGrid::Accessor& acc, const BlockLattice& cells, const openvdb::Coord& lo,
               const openvdb::Coord& hi, float v) {
  const openvdb::Coord a = cell_of(cells, lo.offsetBy(-1));
  const openvdb::Coord b = cell_of(cells, hi.offsetBy(1));
  for (int k = a.z(); k <= b.z(); ++k)
    for (int j = a.y(); j <= b.y(); ++j)
      for (int i = a.x(); i <= b.x(); ++i) raise(acc, openvdb::Coord(i, j, k), v);
}

/// The cells anchored at the lower corner of the channels' active voxels (of their union; index
/// 0 when nothing is active): docs/render.md §5 "Majorant cells anchored to the cloth".
BlockLattice anchored_cells(const std::vector<const Grid*>& channels) {
  IndexBox box;
  bool any = false;
  for (const Grid* c : channels) {
    const IndexBox b = c->active_bbox();
    if (b.empty()) continue;
    for (std::size_t a = 0; a < 3; ++a) box.min[a] = any ? std::min(box.min[a], b.min[a]) : b.min[a];
    any = true;
  }
  return block_lattice(box, MajorantGrid::kBlock);
}

}  // namespace

MajorantGrid::MajorantGrid(const Grid& grid) : MajorantGrid(std::vector<const Grid*>{&grid}) {}

MajorantGrid::MajorantGrid(const std::vector<const Grid*>& channels) {
  ensure_openvdb_initialized();
  if (channels.empty()) fail("majorant grid: no grid");
  const Grid& grid = *channels.front();
  for (const Grid* c : channels) {
    if (c->voxel_size() != grid.voxel_size() || c->origin() != grid.origin())
      fail("majorant grid: grids '{}' and '{}' differ in voxel size or origin", grid.name(), c->name());
  }
  auto coarse = openvdb::FloatGrid::create(0.0F);
  // Cell K covers fine voxels anchor + 8K … anchor + 8K + 7, i.e. world corner + 8h·[K, K+1)
  // with corner = origin + h·anchor; OpenVDB places voxel centres, so the coarse transform is
  // scale 8h with cell K centred at corner + 8h·(K + ½).
  const double h = grid.voxel_size();
  const BlockLattice cells = anchored_cells(channels);
  const auto corner = cells.coarse_origin(grid.origin(), h);
  auto xf = openvdb::math::Transform::createLinearTransform(kBlock * h);
  xf->postTranslate(
      openvdb::Vec3d(corner[0] + 0.5 * kBlock * h, corner[1] + 0.5 * kBlock * h, corner[2] + 0.5 * kBlock * h));
  coarse->setTransform(xf);
  coarse->setName(grid.name() + "_majorant");
  auto acc = coarse->getAccessor();
  float global = 0.0F;
  constexpr float kNone = -std::numeric_limits<float>::infinity();
  // Raising is a maximum, so every channel raising the same cells gives the maximum over the
  // channels of the per-voxel values.
  for (const Grid* channel : channels) {
    const openvdb::FloatGrid& fine = *channel->impl().grid;
    // Voxels: a leaf overlaps at most 2 cells per axis (the cells are leaf-sized but anchored to
    // the cloth, not to the leaves); each cell's maximum over the leaf goes to it in one write,
    // and voxels on a cell's faces also raise the neighbouring cells (the one-voxel dilation).
    for (auto leaf = fine.tree().cbeginLeaf(); leaf; ++leaf) {
      const openvdb::Coord first = cell_of(cells, leaf->origin());
      std::array<float, 8> cell_max;
      cell_max.fill(kNone);
      for (auto it = leaf->cbeginValueOn(); it; ++it) {
        const float v = *it;
        const openvdb::Coord c = it.getCoord();
        const openvdb::Coord cell = cell_of(cells, c);
        const openvdb::Coord rel = c - openvdb::Coord(static_cast<openvdb::Int32>(cells.first_voxel(0, cell.x())),
                                                      static_cast<openvdb::Int32>(cells.first_voxel(1, cell.y())),
                                                      static_cast<openvdb::Int32>(cells.first_voxel(2, cell.z())));
        const openvdb::Coord slot = cell - first;  // 0 or 1 per axis
        const int index = slot.x() + 2 * slot.y() + 4 * slot.z();
        float& m = cell_max[static_cast<std::size_t>(index)];
        m = std::max(m, v);
        const bool face = rel.x() == 0 || rel.y() == 0 || rel.z() == 0 || rel.x() == kBlock - 1 ||
                          rel.y() == kBlock - 1 || rel.z() == kBlock - 1;
        if (face) raise_box(acc, cells, c, c, v);
      }
      for (std::size_t s = 0; s < cell_max.size(); ++s) {
        if (cell_max[s] == kNone) continue;
        const auto o = static_cast<int>(s);
        raise(acc, first.offsetBy(o & 1, (o >> 1) & 1, (o >> 2) & 1), cell_max[s]);
        global = std::max(global, cell_max[s]);
      }
    }
    // Active tiles (constant over 128³ or 4096³ voxels): every cell they touch, dilated.
    auto tiles = fine.tree().cbeginValueOn();
    tiles.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
      openvdb::CoordBBox bb;
      tiles.getBoundingBox(bb);
      raise_box(acc, cells, bb.min(), bb.max(), *tiles);
      global = std::max(global, *tiles);
    }
  }
  max_value_ = std::max(0.0, static_cast<double>(global));
  cells_ = std::make_unique<Grid>(wrap_openvdb(coarse));
}

MajorantGrid::~MajorantGrid() = default;
MajorantGrid::MajorantGrid(MajorantGrid&&) noexcept = default;
MajorantGrid& MajorantGrid::operator=(MajorantGrid&&) noexcept = default;

std::uint64_t MajorantGrid::active_cells() const { return cells_->active_voxel_count(); }

namespace {
/// World-space lookups of the voxel containing a point, through a LeafCachedReader: a ray's
/// tentative collisions come in order along it, so most read the leaf buffer of the one before,
/// and the accessor (whose own cache check and node probing were ~30 % of a cloth render's time,
/// perf) is asked only when a point falls in another leaf (the ray crossed a leaf face) or in a
/// tile.
struct PointLookup {
  LeafCachedReader reader;
  double origin[3];
  double inv_h;
  explicit PointLookup(const Grid& grid) : reader(*grid.impl().grid) {
    const auto o = grid.origin();
    for (int a = 0; a < 3; ++a) origin[a] = o[a];
    inv_h = 1.0 / grid.voxel_size();
  }
  double operator()(double x, double y, double z) {
    return static_cast<double>(
        reader.value(openvdb::Coord(static_cast<openvdb::Int32>(std::floor((x - origin[0]) * inv_h)),
                                    static_cast<openvdb::Int32>(std::floor((y - origin[1]) * inv_h)),
                                    static_cast<openvdb::Int32>(std::floor((z - origin[2]) * inv_h)))));
  }
};

/// The unit direction of a ray (the DDA measures t along it).
std::array<double, 3> unit(const Ray& ray) {
  const auto& d = ray.direction;
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return {d[0] / len, d[1] / len, d[2] / len};
}
}  // namespace

struct MajorantTracker::Impl {
  openvdb::FloatGrid::ConstPtr coarse;
  detail::Accessor coarse_acc;
  detail::CellBox box;
  detail::CellMap map;
  std::vector<PointLookup> lookups;  // one per channel
  Impl(const std::vector<const Grid*>& channels, const MajorantGrid& m)
      : coarse(m.cells().impl().grid),
        coarse_acc(coarse->getConstAccessor()),
        box(detail::active_cell_box(*coarse)),
        map(*coarse) {
    lookups.reserve(channels.size());
    for (const Grid* c : channels) lookups.emplace_back(*c);
  }
};

MajorantTracker::MajorantTracker(const Grid& grid, const MajorantGrid& majorants)
    : MajorantTracker(std::vector<const Grid*>{&grid}, majorants) {}
MajorantTracker::MajorantTracker(const std::vector<const Grid*>& channels, const MajorantGrid& majorants)
    : impl_(std::make_unique<Impl>(channels, majorants)) {}
MajorantTracker::~MajorantTracker() = default;
MajorantTracker::MajorantTracker(MajorantTracker&&) noexcept = default;
MajorantTracker& MajorantTracker::operator=(MajorantTracker&&) noexcept = default;

void MajorantTracker::walk(const Ray& ray, double t0, double t1, FunctionRef<bool(double, double, double)> visit) {
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  detail::march_cells(impl_->coarse_acc, r, impl_->box, t0, t1,
                      [&](double a, double b, float v, const std::int64_t*, int) {
                        ++counters_.cells;
                        return visit(a, b, static_cast<double>(v));
                      });
}

double MajorantTracker::value_at(const std::array<double, 3>& x) { return impl_->lookups[0](x[0], x[1], x[2]); }

namespace {

// The tentative collisions of a ray through the majorant cells (delta and ratio tracking share
// them, pbrt-v4's SampleT_maj): in each cell of majorant μ̄ = scale·v, exponential steps of rate
// μ̄ (memoryless, so a flight that leaves a cell restarts at its face with the next cell's
// rate); at each, `at(t, mu, majorant)` gets the density's μ there (scale·lookup(x, y, z): one
// channel, or the weighted channels) and returns false to stop.
template <typename Lookup, typename At>
void for_each_tentative(const detail::CellRay& r, detail::Accessor& coarse_acc, const detail::CellBox& box,
                        const Ray& ray, double t0, double t1, double scale, Pcg32& rng, Lookup&& lookup,
                        TrackerCounters& counters, At&& at) {
  const auto d = unit(ray);
  const auto& o = ray.origin;
  detail::march_cells(coarse_acc, r, box, t0, t1, [&](double a, double b, float v, const std::int64_t*, int) {
    ++counters.cells;
    if (!(v > 0.0F)) return true;
    const double majorant = scale * static_cast<double>(v);
    double t = a;
    for (;;) {
      t += -std::log(rng.uniform_open()) / majorant;
      if (t >= b) return true;
      ++counters.lookups;
      const double mu = scale * lookup(o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]);
      if (!at(t, mu, majorant)) return false;
    }
  });
}

/// Σ_c w_c·value_c(x): the weighted channels of a direction-dependent grid.
struct WeightedLookup {
  std::vector<PointLookup>& channels;
  const std::vector<double>& weights;
  double operator()(double x, double y, double z) const {
    double v = 0.0;
    for (std::size_t c = 0; c < channels.size(); ++c)
      if (weights[c] > 0.0) v += weights[c] * channels[c](x, y, z);
    return v;
  }
};

void check_weights(const std::vector<double>& weights, std::size_t channels) {
  if (weights.size() != channels) fail("tracking: {} weights for {} channels", weights.size(), channels);
}

template <typename Lookup>
TrackedCollision delta_track_impl(const detail::CellRay& r, detail::Accessor& coarse_acc, const detail::CellBox& box,
                                  const Ray& ray, double t0, double t1, double scale, Pcg32& rng, Lookup&& lookup,
                                  TrackerCounters& counters) {
  TrackedCollision out;
  if (!(scale > 0.0)) return out;
  for_each_tentative(r, coarse_acc, box, ray, t0, t1, scale, rng, lookup, counters,
                     [&](double t, double mu, double majorant) {
                       if (rng.uniform() * majorant < mu) {  // a real collision with probability μ/μ̄
                         out.collided = true;
                         out.t = t;
                         return false;
                       }
                       return true;
                     });
  return out;
}

template <typename Lookup>
double ratio_track_impl(const detail::CellRay& r, detail::Accessor& coarse_acc, const detail::CellBox& box,
                        const Ray& ray, double t0, double t1, double scale, Pcg32& rng, Lookup&& lookup,
                        TrackerCounters& counters) {
  if (!(scale > 0.0)) return 1.0;
  double tr = 1.0;
  for_each_tentative(r, coarse_acc, box, ray, t0, t1, scale, rng, lookup, counters,
                     [&](double, double mu, double majorant) {
                       tr *= std::max(0.0, 1.0 - mu / majorant);
                       if (tr <= 0.0) return false;
                       return ShadowRoulette::keep(tr, rng);
                     });
  return tr;
}

}  // namespace

TrackedCollision MajorantTracker::delta_track(const Ray& ray, double t0, double t1, double scale, Pcg32& rng) {
  Impl& m = *impl_;
  return delta_track_impl(detail::to_cell_ray(m.map, ray), m.coarse_acc, m.box, ray, t0, t1, scale, rng, m.lookups[0],
                          counters_);
}

double MajorantTracker::ratio_track(const Ray& ray, double t0, double t1, double scale, Pcg32& rng) {
  Impl& m = *impl_;
  return ratio_track_impl(detail::to_cell_ray(m.map, ray), m.coarse_acc, m.box, ray, t0, t1, scale, rng, m.lookups[0],
                          counters_);
}

TrackedCollision MajorantTracker::delta_track(const Ray& ray, double t0, double t1, double scale,
                                              const std::vector<double>& weights, Pcg32& rng) {
  Impl& m = *impl_;
  check_weights(weights, m.lookups.size());
  return delta_track_impl(detail::to_cell_ray(m.map, ray), m.coarse_acc, m.box, ray, t0, t1, scale, rng,
                          WeightedLookup{m.lookups, weights}, counters_);
}

double MajorantTracker::ratio_track(const Ray& ray, double t0, double t1, double scale,
                                    const std::vector<double>& weights, Pcg32& rng) {
  Impl& m = *impl_;
  check_weights(weights, m.lookups.size());
  return ratio_track_impl(detail::to_cell_ray(m.map, ray), m.coarse_acc, m.box, ray, t0, t1, scale, rng,
                          WeightedLookup{m.lookups, weights}, counters_);
}

struct DepthTracker::Impl {
  openvdb::FloatGrid::ConstPtr grid;
  detail::Accessor acc;
  detail::CellBox box;
  detail::CellMap map;
  explicit Impl(const Grid& g)
      : grid(g.impl().grid), acc(grid->getConstAccessor()), box(detail::active_cell_box(*grid)), map(*grid) {}
};

DepthTracker::DepthTracker(const Grid& grid) : impl_(std::make_unique<Impl>(grid)) {}
DepthTracker::~DepthTracker() = default;
DepthTracker::DepthTracker(DepthTracker&&) noexcept = default;
DepthTracker& DepthTracker::operator=(DepthTracker&&) noexcept = default;

DepthHit DepthTracker::march_to(const Ray& ray, double t0, double t1, double scale, double tau_star) {
  DepthHit hit;
  hit.t = t1;
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  double tau = 0.0;
  detail::march_cells(impl_->acc, r, impl_->box, t0, t1, [&](double a, double b, float v, const std::int64_t*, int) {
    ++counters_.cells;
    const double mu = scale * static_cast<double>(v);
    const double dtau = mu * (b - a);
    if (mu > 0.0 && tau + dtau >= tau_star) {
      hit.reached = true;
      hit.t = a + (tau_star - tau) / mu;  // τ is linear inside the voxel
      tau = tau_star;
      return false;
    }
    tau += dtau;
    return true;
  });
  hit.tau = tau;
  return hit;
}

double DepthTracker::optical_depth(const Ray& ray, double t0, double t1, double scale) {
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  double tau = 0.0;
  detail::march_cells(impl_->acc, r, impl_->box, t0, t1, [&](double a, double b, float v, const std::int64_t*, int) {
    ++counters_.cells;
    tau += (b - a) * static_cast<double>(v);
    return true;
  });
  return tau * scale;
}

double DepthTracker::transmittance(const Ray& ray, double t0, double t1, double scale, Pcg32& rng) {
  const detail::CellRay r = detail::to_cell_ray(impl_->map, ray);
  ShadowRoulette roulette;
  double tau = 0.0;
  bool ended = false;
  detail::march_cells(impl_->acc, r, impl_->box, t0, t1, [&](double a, double b, float v, const std::int64_t*, int) {
    ++counters_.cells;
    if (!(v > 0.0F)) return true;
    tau += scale * static_cast<double>(v) * (b - a);
    ended = !roulette.keep_depth(tau, rng);
    return !ended;
  });
  return ended ? 0.0 : roulette.estimate(tau);
}

}  // namespace weft::volume
