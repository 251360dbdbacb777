#include "weft/render/local_gamma.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <openvdb/openvdb.h>

#include "weft/core/error.h"
#include "weft/volume/grid_openvdb.h"

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
  // Concentrations and variances are >= 0 by definition; a negative or NaN value is a broken file.
  auto check = [&](const volume::Grid& grid) {
    const auto& g = *grid.impl().grid;
    if (!(g.background() >= 0.0F))
      fail("local-gamma medium '{}': grid '{}' has a negative or NaN background", vdb.string(), grid.name());
    for (auto it = g.cbeginValueOn(); it; ++it) {
      if (!(*it >= 0.0F)) {
        const openvdb::Coord c = it.getCoord();
        fail("local-gamma medium '{}': grid '{}' has value {} at voxel ({}, {}, {}); values must be >= 0 and not NaN",
             vdb.string(), grid.name(), static_cast<double>(*it), c.x(), c.y(), c.z());
      }
    }
  };
  check(*mean_);
  for (const auto& v : var_) check(*v);
  tracer_ = std::make_unique<volume::Tracer>(*mean_);
}

std::unique_ptr<LocalGammaField> LocalGammaField::clone() const {
  std::unique_ptr<LocalGammaField> f(new LocalGammaField());
  f->mean_ = mean_;
  f->var_ = var_;
  f->sigma_ = sigma_;
  f->tracer_ = std::make_unique<volume::Tracer>(*mean_);
  return f;
}

template <typename Piece>
void LocalGammaField::walk(const volume::Ray& ray, double t0, double t1, transmittance::Origin origin, Piece&& piece) {
  const bool scatterer = origin == transmittance::Origin::scatterer;
  const auto& d = ray.direction;
  const int axis = std::abs(d[0]) >= std::abs(d[1]) ? (std::abs(d[0]) >= std::abs(d[2]) ? 0 : 2)
                                                    : (std::abs(d[1]) >= std::abs(d[2]) ? 1 : 2);
  const volume::Grid& var = *var_[static_cast<std::size_t>(axis)];
  tracer_->march(ray, t0, t1, [&](const volume::Segment& s) {
    const double mean = s.value;
    if (!(mean > 0.0)) return true;
    const double v = var.value(s.voxel[0], s.voxel[1], s.voxel[2]);
    // Σ_Q(s) = σα/(β + σs) = σC̄/(1 + κs) with κ = σV/C̄ (α = C̄²/V, β = C̄/V); the partner
    // T_S = (1 + κs)^{−(α+1)} has Σ_S = (α + 1)κ/(1 + κs) = (σC̄ + κ)/(1 + κs).
    const double kappa = sigma_ * v / mean;
    return piece(s.t0 - t0, s.t1 - t0, sigma_ * mean + (scatterer ? kappa : 0.0), kappa);
  });
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
