#include "weft/render/local_gamma.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "weft/core/error.h"

namespace weft::render {

LocalGammaField::LocalGammaField(const std::filesystem::path& vdb, double sigma) : sigma_(sigma) {
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
  make_accessors();
}

void LocalGammaField::make_accessors() {
  tracer_ = std::make_unique<volume::Tracer>(*mean_);
  for (std::size_t a = 0; a < 3; ++a) var_readers_[a] = std::make_unique<volume::VoxelReader>(*var_[a]);
}

std::unique_ptr<LocalGammaField> LocalGammaField::clone() const {
  std::unique_ptr<LocalGammaField> f(new LocalGammaField());
  f->mean_ = mean_;
  f->var_ = var_;
  f->sigma_ = sigma_;
  f->make_accessors();
  return f;
}

template <typename Piece>
void LocalGammaField::walk(const volume::Ray& ray, double t0, double t1, transmittance::Origin origin, Piece&& piece) {
  const bool scatterer = origin == transmittance::Origin::scatterer;
  const auto& d = ray.direction;
  const int axis = std::abs(d[0]) >= std::abs(d[1]) ? (std::abs(d[0]) >= std::abs(d[2]) ? 0 : 2)
                                                    : (std::abs(d[1]) >= std::abs(d[2]) ? 1 : 2);
  volume::VoxelReader& var = *var_readers_[static_cast<std::size_t>(axis)];
  // Pulled segment by segment (volume::Tracer::start/next): the piece below inlines here, no
  // callback object per flight.
  tracer_->start(ray, t0, t1);
  volume::Segment s;
  while (tracer_->next(s)) {
    const double mean = s.value;
    if (!(mean > 0.0)) continue;
    const double v = var.value(s.voxel);
    // Σ_Q(s) = σα/(β + σs) = σC̄/(1 + κs) with κ = σV/C̄ (α = C̄²/V, β = C̄/V); the partner
    // T_S = (1 + κs)^{−(α+1)} has Σ_S = (α + 1)κ/(1 + κs) = (σC̄ + κ)/(1 + κs).
    const double kappa = sigma_ * v / mean;
    if (!piece(s.t0 - t0, s.t1 - t0, sigma_ * mean + (scatterer ? kappa : 0.0), kappa)) return;
  }
}

namespace {
/// ∫_a^b σC̄/(1 + κs) ds.
double piece_hazard(double a, double b, double rate, double kappa) {
  if (kappa == 0.0) return rate * (b - a);
  return rate / kappa * std::log1p(kappa * (b - a) / (1.0 + kappa * a));
}
}  // namespace

double LocalGammaField::log_transmittance(const volume::Ray& ray, double t0, double t1, transmittance::Origin origin) {
  double h = 0.0;
  walk(ray, t0, t1, origin, [&](double a, double b, double rate, double kappa) {
    h += piece_hazard(a, b, rate, kappa);
    return true;
  });
  return -h;
}

double LocalGammaField::sample_distance(const volume::Ray& ray, double t0, double t1, double h,
                                        transmittance::Origin origin) {
  double acc = 0.0;
  double hit = std::numeric_limits<double>::infinity();
  walk(ray, t0, t1, origin, [&](double a, double b, double rate, double kappa) {
    const double dh = piece_hazard(a, b, rate, kappa);
    if (acc + dh < h) {
      acc += dh;
      return true;
    }
    const double rest = h - acc;
    // Inverse of the piece's hazard: rate/κ·log((1+κs)/(1+κa)) = rest.
    const double s = kappa == 0.0 ? a + rest / rate : a + (1.0 + kappa * a) * std::expm1(rest * kappa / rate) / kappa;
    hit = t0 + std::min(s, b);
    return false;
  });
  return hit;
}

}  // namespace weft::render
