#include "weft/render/local_gamma.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "weft/core/error.h"
#include "weft/volume/dense.h"
#include "weft/volume/majorants.h"

namespace weft::render {

LocalGammaField::LocalGammaField(const std::filesystem::path& vdb, double sigma, transmittance::MemoryRule memory,
                                 std::uint64_t max_dense_bytes)
    : sigma_(sigma), memory_(memory) {
  if (!(std::isfinite(sigma) && sigma > 0.0))
    fail("local-gamma medium '{}': sigma must be finite and > 0", vdb.string());
  try {
    mean_ = std::make_shared<const volume::Grid>(volume::Grid::load(vdb, "mean_concentration"));
    for (int a = 0; a < 3; ++a)
      var_[static_cast<std::size_t>(a)] =
          std::make_shared<const volume::Grid>(volume::Grid::load(vdb, std::string("var_concentration_") + "xyz"[a]));
  } catch (const Error& e) {
    fail("local-gamma medium: {}", e.what());
  }
  if (mean_->active_voxel_count() == 0) fail("local-gamma medium '{}': mean_concentration is empty", vdb.string());
  // Concentrations and variances are >= 0 by definition; Grid::load refuses a negative, NaN or
  // infinite value and a non-zero background (naming the grid and the voxel), so a broken file
  // has already failed above with the medium named.
  make_dense(max_dense_bytes);
  make_accessors();
}

void LocalGammaField::make_dense(std::uint64_t max_dense_bytes) {
  volume::detail::IndexMap map;
  if (!volume::dense_walk_map(*mean_, map)) return;
  const volume::IndexBox box = mean_->active_bbox();
  const std::uint64_t voxels = volume::dense_bytes(box) / sizeof(float);
  if (voxels > max_dense_bytes / sizeof(Record)) return;
  // The records hold the grids' own floats, so both walks enter the same numbers.
  const std::vector<float> mean = volume::to_dense(*mean_, box, max_dense_bytes);
  auto records = std::make_shared<std::vector<Record>>(mean.size());
  for (std::size_t i = 0; i < mean.size(); ++i) (*records)[i].mean = mean[i];
  for (std::size_t a = 0; a < 3; ++a) {
    const std::vector<float> var = volume::to_dense(*var_[a], box, max_dense_bytes);
    for (std::size_t i = 0; i < mean.size(); ++i) (*records)[i].var[a] = var[i];
  }
  records_ = std::move(records);
  dense_walk_ = volume::DenseWalk(map, box);
  // The medium holds the records only (docs/render.md §6e counts what a representation holds).
  mean_.reset();
  for (auto& v : var_) v.reset();
}

void LocalGammaField::make_accessors() {
  if (dense()) return;
  tracer_ = std::make_unique<volume::Tracer>(*mean_);
  for (std::size_t a = 0; a < 3; ++a) var_readers_[a] = std::make_unique<volume::VoxelReader>(*var_[a]);
}

std::unique_ptr<LocalGammaField> LocalGammaField::clone() const {
  std::unique_ptr<LocalGammaField> f(new LocalGammaField());
  f->mean_ = mean_;
  f->var_ = var_;
  f->sigma_ = sigma_;
  f->memory_ = memory_;
  f->records_ = records_;
  f->dense_walk_ = dense_walk_;
  f->make_accessors();
  return f;
}

template <typename Piece>
void LocalGammaField::walk(const volume::Ray& ray, double t0, double t1, transmittance::GammaHazard& hazard,
                           Piece&& piece) {
  const auto& d = ray.direction;
  const int axis = std::abs(d[0]) >= std::abs(d[1]) ? (std::abs(d[0]) >= std::abs(d[2]) ? 0 : 2)
                                                    : (std::abs(d[1]) >= std::abs(d[2]) ? 1 : 2);
  if (dense()) {
    // The same pieces as the tree walk below over the box's voxels (volume/voxel_walk.h), one
    // record read per piece.
    const Record* records = records_->data();
    const auto a = static_cast<std::size_t>(axis);
    dense_walk_.march(ray, t0, t1, walk_state_, [&](double b0, double b1, std::int64_t index) {
      const Record& r = records[index];
      if (!(r.mean > 0.0f)) return true;
      hazard.enter(sigma_, r.mean, r.var[a], b0 - t0);
      return piece(b0 - t0, b1 - t0);
    });
    return;
  }
  volume::VoxelReader& var = *var_readers_[static_cast<std::size_t>(axis)];
  // Pulled segment by segment (volume::Tracer::start/next): the piece below inlines here, no
  // callback object per flight. Vacuum voxels are skipped: no rule's memory needs them entered.
  tracer_->start(ray, t0, t1);
  volume::Segment s;
  while (tracer_->next(s)) {
    const double mean = s.value;
    if (!(mean > 0.0)) continue;
    hazard.enter(sigma_, mean, var.value(s.voxel), s.t0 - t0);
    if (!piece(s.t0 - t0, s.t1 - t0)) return;
  }
}

double LocalGammaField::log_transmittance(const volume::Ray& ray, double t0, double t1, transmittance::Origin origin) {
  transmittance::GammaHazard hazard(memory_, origin);
  walk(ray, t0, t1, hazard, [&](double a, double b) {
    hazard.advance(a, b);
    return true;
  });
  return -hazard.hazard();
}

double LocalGammaField::transmittance(const volume::Ray& ray, double t0, double t1, transmittance::Origin origin,
                                      Pcg32& rng) {
  transmittance::GammaHazard hazard(memory_, origin);
  volume::ShadowRoulette roulette;
  bool ended = false;
  walk(ray, t0, t1, hazard, [&](double a, double b) {
    hazard.advance(a, b);
    ended = !roulette.keep_depth(hazard.hazard(), rng);
    return !ended;
  });
  return ended ? 0.0 : roulette.estimate(hazard.hazard());
}

void LocalGammaField::log_transmittance_profile(const volume::Ray& ray, double t0, std::span<const double> ends,
                                                std::span<double> out, transmittance::Origin origin) {
  if (out.size() != ends.size()) fail("local-gamma profile: {} outputs for {} ends", out.size(), ends.size());
  const std::size_t n = ends.size();
  std::size_t k = 0;
  transmittance::GammaHazard hazard(memory_, origin);
  if (n > 0 && ends[n - 1] > t0) {
    // Pieces come in order and vacuum is skipped: an end before a piece has the hazard so far,
    // an end inside it the hazard so far plus the part of the piece up to it.
    walk(ray, t0, ends[n - 1], hazard, [&](double a, double b) {
      for (; k < n && ends[k] - t0 <= a; ++k) out[k] = -hazard.hazard();
      for (; k < n && ends[k] - t0 < b; ++k) out[k] = -(hazard.hazard() + hazard.piece(a, ends[k] - t0));
      hazard.advance(a, b);
      return k < n;
    });
  }
  for (; k < n; ++k) out[k] = -hazard.hazard();
}

double LocalGammaField::sample_distance(const volume::Ray& ray, double t0, double t1, double h,
                                        transmittance::Origin origin) {
  transmittance::GammaHazard hazard(memory_, origin);
  double hit = std::numeric_limits<double>::infinity();
  walk(ray, t0, t1, hazard, [&](double a, double b) {
    const double x = hazard.advance_until(a, b, h);
    if (std::isinf(x)) return true;
    hit = t0 + x;
    return false;
  });
  return hit;
}

}  // namespace weft::render
