#include "weft/render/integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>

#include "weft/render/environment.h"
#include "weft/render/frame.h"
#include "weft/render/phase.h"

namespace weft::render {

using transmittance::Origin;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kMaxNullCrossings = 1024;

double power_heuristic(double a, double b) {
  const double a2 = a * a;
  const double b2 = b * b;
  return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

double fresnel_dielectric(double cos_i, double eta) {
  // eta = n_t / n_i; exact unpolarised Fresnel reflectance.
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

/// The flight and the shadow of a medium. In the exponential specialisation render() checked
/// that every medium is an ExponentialMedium (its traits say so): the final class's own
/// functions are called, inlined, with no virtual dispatch.
template <bool kGeneral>
Flight sample_flight(const Medium& m, const Vec3& o, const Vec3& d, double t_max, Origin origin, Pcg32& rng,
                     MediumScratch* scratch) {
  if constexpr (kGeneral) {
    return m.sample_flight(o, d, t_max, origin, rng, scratch);
  } else {
    return static_cast<const ExponentialMedium&>(m).sample_flight(o, d, t_max, origin, rng, scratch);
  }
}

template <bool kGeneral>
double medium_transmittance(const Medium& m, const Vec3& o, const Vec3& d, double t, Origin origin, Pcg32& rng,
                            MediumScratch* scratch) {
  if constexpr (kGeneral) {
    return m.transmittance(o, d, t, origin, rng, scratch);
  } else {
    return static_cast<const ExponentialMedium&>(m).transmittance(o, d, t, origin, rng, scratch);
  }
}

/// A path whose throughput is zero in every channel carries nothing: it ends at once (an
/// albedo-0 medium would otherwise be traced to the roulette depth for no contribution).
bool dead(const Rgb& beta) { return !(beta != 0.0).any(); }

}  // namespace

template <bool kMedia, bool kNonExp>
Rgb Integrator<kMedia, kNonExp>::li(Vec3 o, Vec3 d, Pcg32& rng, PathCounters& counters) const {
  Rgb radiance(0, 0, 0);
  Rgb beta(1, 1, 1);
  int medium = w_.camera_medium;  // found once from the boundaries around the camera (world.cpp)
  Origin origin = Origin::source;
  bool specular = true;  // the previous direction was not sampled by a density (camera, mirror, glass)
  double prev_pdf = 0.0;
  Vec3 prev_point = o;
  double tmin = 0.0;
  int depth = 0;
  int null_crossings = 0;
  const double light_select = w_.lights.empty() ? 0.0 : 1.0 / static_cast<double>(w_.lights.size());

  // The ray has just left the scene's one convex shape outward: it can hit nothing more.
  bool escaped = false;
  for (;;) {
    const bool skip_query = std::exchange(escaped, false);  // only the ray straight after the exit
    std::optional<SurfaceHit> hit;
    bool queried = false;
    const auto query = [&] {
      queried = true;
      if (skip_query) return;
      ++counters.rays;
      hit = w_.geometry->intersect(o, d, tmin, std::numeric_limits<double>::infinity());
    };

    if constexpr (kMedia) {
      if (medium >= 0) {
        const Medium& m = *w_.media[static_cast<std::size_t>(medium)];
        MediumScratch* scratch = counters.scratch[static_cast<std::size_t>(medium)].get();
        Flight flight;
        if constexpr (kNonExp) {
          query();
          flight = sample_flight<kNonExp>(m, o, d, hit ? hit->t : std::numeric_limits<double>::infinity(), origin, rng,
                                          scratch);
        } else {
          // An exponential flight's distance is drawn without the boundary (one draw, as
          // sample_flight draws it) and collides exactly when it ends before the next surface;
          // within the geometry's clearance along the ray no surface can come first, so the
          // closest hit is needed only beyond it (docs/render.md §1, "Queries a path skips").
          // Same draws, same decisions, same bytes.
          const auto& em = static_cast<const ExponentialMedium&>(m);
          flight.t = em.sample_distance(rng);
          flight.collided = flight.t < w_.geometry->clearance(o, d);
          if (!flight.collided) {
            query();
            const double t_hit = hit ? hit->t : std::numeric_limits<double>::infinity();
            flight.collided = flight.t < t_hit;
            if (!flight.collided) flight.t = t_hit;
          }
        }
        beta *= flight.weight;
        if (dead(beta)) break;
        if (flight.collided) {
          const double t = flight.t;
          const Vec3 x = o + t * d;
          beta *= m.albedo();
          if (dead(beta)) break;
          origin = Origin::scatterer;
          if (++depth > w_.settings.max_depth) break;
          // Next-event estimation with MIS against phase sampling.
          if (!w_.lights.empty()) {
            const LightSample ls = w_.lights.sample(x, *w_.geometry, rng);
            if (ls.pdf > 0.0 && (ls.le > 0.0).any()) {
              const double f = hg(m.g(), d.dot(ls.wi));
              const double tr = shadow(x, ls, medium, Origin::scatterer, rng, counters);
              if (tr > 0.0) {
                const double mis = ls.delta ? 1.0 : power_heuristic(ls.pdf, f);
                radiance += beta * ls.le * (f * tr * mis / ls.pdf);
              }
            }
          }
          const Vec3 wi = sample_hg(m.g(), d, rng);  // weight f/pdf = 1
          prev_pdf = hg(m.g(), d.dot(wi));
          specular = false;
          prev_point = x;
          o = x;
          d = wi;
          tmin = 0.0;
          if (!roulette(beta, depth, rng)) break;
          continue;
        }
      }
    }

    if (!queried) query();
    if (!hit) {
      if (w_.lights.environment_light >= 0) {
        const EnvironmentMap* map = w_.lights.environment_map.get();
        const double env_pdf = map != nullptr ? map->pdf(d) : 1.0 / (4.0 * kPi);
        const double mis = specular ? 1.0 : power_heuristic(prev_pdf, light_select * env_pdf);
        radiance += beta * (map != nullptr ? map->radiance(d) : w_.lights.environment) * mis;
      }
      break;
    }

    const ShapeInfo& shape = w_.geometry->shapes()[static_cast<std::size_t>(hit->shape)];
    const Vec3 wo = -d;
    const double cos_o = hit->n.dot(wo);
    // Emission from the front side (area lights).
    if ((shape.emission > 0.0).any() && cos_o > 0.0) {
      double mis = 1.0;
      if (!specular) {
        const double dist2 = (hit->p - prev_point).squaredNorm();
        const double light_pdf = light_select * dist2 / (shape.area * cos_o);
        mis = power_heuristic(prev_pdf, light_pdf);
      }
      radiance += beta * shape.emission * mis;
    }
    if (shape.material < 0) break;  // a pure emitter absorbs
    const bool entering = cos_o > 0.0;

    if (shape.null_material) {
      // An index-matched boundary: the ray goes on unchanged, in the medium on the far side;
      // correlation with the old medium's particles is lost, so the next flight is from a source.
      if (++null_crossings > kMaxNullCrossings) break;
      if constexpr (kMedia) {
        medium = entering ? shape.interior : shape.exterior;
        origin = Origin::source;
      }
      escaped = !entering && w_.geometry->lone_convex();
      o = offset(*hit, d);
      tmin = 0.0;
      continue;
    }

    const MaterialDesc& mat = w_.materials[static_cast<std::size_t>(shape.material)];
    if (++depth > w_.settings.max_depth) break;
    origin = Origin::source;
    const Vec3 n = entering ? hit->n : Vec3(-hit->n);  // faces the incoming side

    if (mat.kind == MaterialKind::diffuse) {
      if (!w_.lights.empty()) {
        const LightSample ls = w_.lights.sample(hit->p, *w_.geometry, rng);
        const double cos_i = n.dot(ls.wi);
        if (ls.pdf > 0.0 && cos_i > 0.0 && (ls.le > 0.0).any()) {
          const double tr = shadow(offset(*hit, ls.wi), ls, medium, Origin::source, rng, counters);
          if (tr > 0.0) {
            const double f_pdf = cos_i / kPi;
            const double mis = ls.delta ? 1.0 : power_heuristic(ls.pdf, f_pdf);
            radiance += beta * mat.albedo * ls.le * (cos_i / kPi * tr * mis / ls.pdf);
          }
        }
      }
      // Cosine-weighted sampling: weight f·cos/pdf = albedo.
      const double r = std::sqrt(rng.uniform());
      const double phi = 2.0 * kPi * rng.uniform();
      const double z = std::sqrt(std::max(0.0, 1.0 - r * r));
      d = from_frame(n, r * std::cos(phi), r * std::sin(phi), z).normalized();
      prev_pdf = z / kPi;
      specular = false;
      beta *= mat.albedo;
    } else if (mat.kind == MaterialKind::mirror) {
      d = (d - 2.0 * d.dot(n) * n).normalized();
      specular = true;
      beta *= mat.albedo;
    } else {                                                  // dielectric
      const double eta = entering ? mat.ior : 1.0 / mat.ior;  // n_t / n_i
      const double cos_i = std::abs(cos_o);
      const double fr = fresnel_dielectric(cos_i, eta);
      if (rng.uniform() < fr) {
        d = (d - 2.0 * d.dot(n) * n).normalized();
      } else {
        const double cos_t = std::sqrt(std::max(0.0, 1.0 - (1.0 - cos_i * cos_i) / (eta * eta)));
        d = (d / eta + (cos_i / eta - cos_t) * n).normalized();
        if constexpr (kMedia) medium = entering ? shape.interior : shape.exterior;
      }
      specular = true;
      beta *= mat.albedo;
    }
    if (dead(beta)) break;
    prev_point = hit->p;
    o = offset(*hit, d);
    tmin = 0.0;
    if (!roulette(beta, depth, rng)) break;
  }
  return radiance;
}

template <bool kMedia, bool kNonExp>
Vec3 Integrator<kMedia, kNonExp>::offset(const SurfaceHit& hit, const Vec3& dir) const {
  const double scale = w_.geometry->spawn_offset(hit.p, hit.shape);
  return hit.p + (hit.n.dot(dir) > 0.0 ? scale : -scale) * hit.n;
}

template <bool kMedia, bool kNonExp>
bool Integrator<kMedia, kNonExp>::roulette(Rgb& beta, int depth, Pcg32& rng) const {
  if (depth < w_.settings.rr_depth) return true;
  const double q = std::min(1.0, beta.maxCoeff());
  if (q >= 1.0) return true;
  if (q <= 0.0 || rng.uniform() >= q) return false;
  beta /= q;
  return true;
}

/// Transmittance of a shadow ray from x (in `medium`, leaving a vertex of kind `origin`) over
/// distance `dist`: null boundaries are crossed (each restarting the flight as from a source),
/// anything else blocks.
template <bool kMedia, bool kNonExp>
double Integrator<kMedia, kNonExp>::shadow(Vec3 x, const LightSample& ls, int medium, Origin origin, Pcg32& rng,
                                           PathCounters& counters) const {
  // A light point (area or point light) is aimed at from each segment's own origin
  // (docs/render.md §2, "Shadow rays to a light point"): the origin is offset off the surface it
  // leaves (a diffuse vertex, each null boundary crossed), and a ray kept along ls.wi from there
  // passes beside the light point, so the distance to that point no longer bounds the distance
  // to the light's surface; re-aimed, the segment ends ls.margin short of the point on the line
  // through it, which a flat or convex emitter seen from its front does not cross. Lights at
  // infinity keep ls.wi.
  const bool finite = std::isfinite(ls.dist);
  Vec3 wi = ls.wi;
  double dist = ls.dist;
  const auto aim = [&] {
    const Vec3 to = ls.point - x;
    const double length = to.norm();
    if (length > 0.0) wi = to / length;
    dist = std::max(0.0, length - ls.margin);
  };
  if (finite) aim();
  double tmin = 0.0;
  if constexpr (!kMedia) {
    if (!w_.any_null) {
      ++counters.rays;
      return w_.geometry->occluded(x, wi, tmin, dist) ? 0.0 : 1.0;
    }
  }
  double tr = 1.0;
  double remaining = dist;
  bool escaped = false;  // as in li(): out of the scene's one convex shape, nothing more to hit
  for (int crossing = 0; crossing <= kMaxNullCrossings; ++crossing) {
    std::optional<SurfaceHit> hit;
    if (!escaped) {
      ++counters.rays;
      hit = w_.geometry->intersect(x, wi, tmin, remaining);
    }
    const double segment = hit ? hit->t : remaining;
    if constexpr (kMedia) {
      if (medium >= 0) {
        tr *= medium_transmittance<kNonExp>(*w_.media[static_cast<std::size_t>(medium)], x, wi, segment, origin, rng,
                                            counters.scratch[static_cast<std::size_t>(medium)].get());
        if (!(tr > 0.0)) return 0.0;
      }
    }
    if (!hit) return tr;
    const ShapeInfo& s = w_.geometry->shapes()[static_cast<std::size_t>(hit->shape)];
    if (!s.null_material) return 0.0;
    const bool entering = hit->n.dot(wi) < 0.0;
    if constexpr (kMedia) {
      medium = entering ? s.interior : s.exterior;
      origin = Origin::source;
    }
    escaped = !entering && w_.geometry->lone_convex();
    x = offset(*hit, wi);
    if (finite) {
      aim();
      remaining = dist;
    }
    tmin = 0.0;
    if (!(remaining > 0.0)) return tr;
  }
  return 0.0;
}

template class Integrator<false, false>;
template class Integrator<true, false>;
template class Integrator<true, true>;

}  // namespace weft::render
