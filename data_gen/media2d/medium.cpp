#include "data_gen/media2d/medium.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "weft/core/error.h"
#include "weft/core/number_name.h"

namespace weft::media2d {
namespace {

constexpr std::size_t kMinParticles = 16;
constexpr std::size_t kMaxParticles = 50'000'000;

// ω s with ω uniform on the circle and s = −log(ξ)·mean: the step law of S.11.1.
Point2 random_step(Pcg32& rng, double mean) {
  const double s = -std::log(rng.uniform_open()) * mean;
  const double phi = 2.0 * std::numbers::pi * rng.uniform();
  return {s * std::cos(phi), s * std::sin(phi)};
}

Point2 wrapped(Point2 p) { return {wrap_unit(p.x), wrap_unit(p.y)}; }

}  // namespace

double wrap_unit(double x) {
  double w = x - std::floor(x);
  // x slightly below an integer can round to exactly 1.0.
  if (w >= 1.0) w = 0.0;
  return w;
}

Point2 periodic_delta(Point2 a, Point2 b) {
  double dx = b.x - a.x;
  double dy = b.y - a.y;
  dx -= std::round(dx);
  dy -= std::round(dy);
  return {dx, dy};
}

std::size_t particle_count(double radius, double mean_free_path) {
  // λ = (1 − nπr²)/(2nr) ⇔ n (2rλ + πr²) = 1.
  const double n = 1.0 / (2.0 * radius * mean_free_path + std::numbers::pi * radius * radius);
  return static_cast<std::size_t>(std::llround(n));
}

double santalo_mean_free_path(std::size_t count, double radius) {
  const double n = static_cast<double>(count);
  return (1.0 - n * std::numbers::pi * radius * radius) / (2.0 * n * radius);
}

double max_step_unit(double radius) {
  // A step s = −log(ξ)(1 − |η|)² ℓ_step stays below 40 ℓ_step (ξ ≥ 2⁻⁵³: −log ξ < 37), and
  // x + s rounds x by up to s·2⁻⁵³ before the wrap: kept under r / 1000.
  return 1e-3 * radius / (40.0 * 0x1p-53);
}

void validate(const MediumSpec& spec) {
  if (!std::isfinite(spec.eta) || spec.eta < -1.0 || spec.eta >= 1.0) {
    fail("medium: eta must be in [-1, 1), got {}", spec.eta);
  }
  if (!std::isfinite(spec.radius) || spec.radius <= 0.0) fail("medium: radius must be > 0, got {}", spec.radius);
  if (!std::isfinite(spec.mean_free_path) || spec.mean_free_path <= 0.0) {
    fail("medium: mean free path must be > 0, got {}", spec.mean_free_path);
  }
  if (spec.cluster_size == 0) fail("medium: cluster size must be >= 1");
  if (!std::isfinite(spec.step_unit) || spec.step_unit < 0.0) {
    fail("medium: step unit must be >= 0 (0 = mean spacing), got {}", spec.step_unit);
  }
  if (spec.step_unit > max_step_unit(spec.radius)) {
    fail(
        "medium: step unit {} is over {} for radius {}: a step that long, added to a position in [0, 1) and "
        "wrapped, rounds it by more than a thousandth of a disk radius (a step unit past the square's side 1 "
        "already spreads the particles uniformly)",
        spec.step_unit, bound_text(max_step_unit(spec.radius), BoundSide::at_most), spec.radius);
  }
  const double n = 1.0 / (2.0 * spec.radius * spec.mean_free_path + std::numbers::pi * spec.radius * spec.radius);
  if (!(n >= static_cast<double>(kMinParticles))) {
    fail("medium: radius {} and mean free path {} give {:.3g} particles; at least {} are needed", spec.radius,
         spec.mean_free_path, n, kMinParticles);
  }
  if (n > static_cast<double>(kMaxParticles)) {
    fail("medium: radius {} and mean free path {} give {:.3g} particles per realization; at most {} are supported",
         spec.radius, spec.mean_free_path, n, kMaxParticles);
  }
  const double packing = n * std::numbers::pi * spec.radius * spec.radius;
  if (packing > kMaxPackingFraction) {
    fail(
        "medium: packing fraction n*pi*r^2 = {:.4g} exceeds {} (disks would overlap: raise the mean free path "
        "or lower the radius)",
        packing, kMaxPackingFraction);
  }
}

LatticeLayout lattice_layout(const MediumSpec& spec) {
  const std::size_t target = particle_count(spec.radius, spec.mean_free_path);
  // Rows 1/ny apart, columns 1/nx apart: a regular hexagon around each site needs
  // 1/ny = (√3/2)/nx, so nx = √(n√3/2).
  LatticeLayout layout;
  layout.nx = std::max<std::size_t>(
      2, static_cast<std::size_t>(std::llround(std::sqrt(static_cast<double>(target) * std::numbers::sqrt3 / 2.0))));
  std::size_t ny = static_cast<std::size_t>(std::llround(static_cast<double>(target) / static_cast<double>(layout.nx)));
  ny = std::max<std::size_t>(2, ny + (ny % 2));
  layout.ny = ny;
  const double n = static_cast<double>(layout.count());
  // The smallest even k with k/n ≥ 2r: rows then rise by at least one shadow per column, and an
  // even k keeps the half-column offset of alternate rows consistent across the seam.
  auto k = static_cast<std::size_t>(std::ceil(2.0 * spec.radius * n - 1e-9));
  k = std::max<std::size_t>(2, k + (k % 2));
  layout.rise_steps = k;
  layout.rise = static_cast<double>(k) / n;
  return layout;
}

std::vector<Point2> lattice_sites(const LatticeLayout& layout) {
  std::vector<Point2> sites;
  sites.reserve(layout.count());
  const double nx = static_cast<double>(layout.nx);
  const double ny = static_cast<double>(layout.ny);
  for (std::size_t j = 0; j < layout.ny; ++j) {
    const double half = (j % 2 == 1) ? 0.5 : 0.0;
    for (std::size_t i = 0; i < layout.nx; ++i) {
      const double x = (static_cast<double>(i) + half) / nx;
      // (i + half)·k/n from integers, so the seam x = 1 closes exactly: (2i + odd)·k / 2n.
      const std::size_t two_n = 2 * layout.count();
      const std::size_t rise_num = ((2 * i + (j % 2)) * layout.rise_steps) % two_n;
      const double y = static_cast<double>(j) / ny + static_cast<double>(rise_num) / static_cast<double>(two_n);
      sites.push_back({wrap_unit(x), wrap_unit(y)});
    }
  }
  return sites;
}

std::size_t planned_count(const MediumSpec& spec) {
  if (spec.eta < 0.0) return lattice_layout(spec).count();
  return particle_count(spec.radius, spec.mean_free_path);
}

double step_unit(const MediumSpec& spec) {
  if (spec.step_unit > 0.0) return spec.step_unit;
  return 1.0 / std::sqrt(static_cast<double>(planned_count(spec)));
}

Medium generate(const MediumSpec& spec, Pcg32& rng) {
  validate(spec);
  Medium m;
  m.radius = spec.radius;
  m.step_unit = step_unit(spec);
  if (spec.eta < 0.0) {
    m.generator = "lattice";
    m.centers = lattice_sites(lattice_layout(spec));
    const double keep = std::abs(spec.eta);
    const double mean = (1.0 - keep) * (1.0 - keep) * m.step_unit;
    for (auto& c : m.centers) {
      // Perturbed with probability 1 − |η| (S.11.1); the step is drawn only then, so η = −1 consumes
      // one number per site and stays exactly on the lattice.
      if (rng.uniform() < 1.0 - keep) {
        const Point2 step = random_step(rng, mean);
        c = wrapped({c.x + step.x, c.y + step.y});
        ++m.perturbed;
      }
    }
    return m;
  }
  const std::size_t n = particle_count(spec.radius, spec.mean_free_path);
  m.centers.reserve(n);
  if (spec.eta == 0.0) {
    m.generator = "poisson";
    for (std::size_t i = 0; i < n; ++i) {
      const double x = rng.uniform();
      m.centers.push_back({x, rng.uniform()});
    }
    return m;
  }
  m.generator = "random-walk";
  m.cluster_size = std::min(spec.cluster_size, n);
  const double mean = (1.0 - spec.eta) * (1.0 - spec.eta) * m.step_unit;
  Point2 p{};
  for (std::size_t i = 0; i < n; ++i) {
    if (i % m.cluster_size == 0) {
      const double x = rng.uniform();
      p = {x, rng.uniform()};
    } else {
      const Point2 step = random_step(rng, mean);
      p = wrapped({p.x + step.x, p.y + step.y});
    }
    m.centers.push_back(p);
  }
  return m;
}

}  // namespace weft::media2d
