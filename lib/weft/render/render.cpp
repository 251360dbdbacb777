#include "weft/render/render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>

#include <tbb/enumerable_thread_specific.h>

#include "weft/core/error.h"
#include "weft/dist/distributed.h"
#include "weft/render/environment.h"
#include "weft/render/geometry.h"
#include "weft/render/medium.h"

namespace weft::render {

using transmittance::Origin;

std::vector<std::string> Features::names() const {
  std::vector<std::string> out{"surfaces"};
  if (area_lights) out.emplace_back("area lights");
  if (environment) out.emplace_back(environment_image ? "image environment" : "environment");
  if (curves) out.emplace_back("curves");
  // Each medium as it is rendered: kind, law and estimator (asked from the medium).
  for (const auto& m : media_described) out.push_back(m);
  return out;
}

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kMaxNullCrossings = 1024;

/// An orthonormal frame around a unit vector (Duff et al. 2017).
void frame(const Vec3& n, Vec3& s, Vec3& t) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  s = Vec3(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  t = Vec3(b, sign + n.y() * n.y() * a, -n.y());
}

Vec3 from_frame(const Vec3& n, double x, double y, double z) {
  Vec3 s;
  Vec3 t;
  frame(n, s, t);
  return x * s + y * t + z * n;
}

double power_heuristic(double a, double b) {
  const double a2 = a * a;
  const double b2 = b * b;
  return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

/// Henyey–Greenstein phase function of cos θ between the propagation directions before and after.
double hg(double g, double cos_theta) {
  const double d = 1.0 + g * g - 2.0 * g * cos_theta;
  return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

/// Samples a direction from HG around `dir` (exact inversion); the pdf equals hg().
Vec3 sample_hg(double g, const Vec3& dir, Pcg32& rng) {
  const double u = rng.uniform();
  double cos_theta = 0.0;
  if (std::abs(g) < 1e-4) {
    cos_theta = 1.0 - 2.0 * u;
  } else {
    const double q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    cos_theta = std::clamp((1.0 + g * g - q * q) / (2.0 * g), -1.0, 1.0);
  }
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  const double phi = 2.0 * kPi * rng.uniform();
  return from_frame(dir, sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta).normalized();
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

struct Light {
  enum class Kind { area, point, directional, environment } kind = Kind::point;
  int shape = -1;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, -1, 0};
  Rgb radiance{0, 0, 0};
};

struct LightSample {
  Vec3 wi;
  double dist = 0.0;    ///< distance to the light point (∞ for directional/environment)
  Vec3 point{0, 0, 0};  ///< the light point (point and area lights)
  double margin = 0.0;  ///< a shadow ray stops this far short of an area light's surface
  Rgb le{0, 0, 0};
  double pdf = 0.0;  ///< solid-angle pdf including the light selection probability
  bool delta = false;
};

struct Camera {
  Vec3 position, forward, right, up;
  double tan_half = 0.0, aspect = 1.0, lens_radius = 0.0, focus = 1.0;
  int width = 1, height = 1;

  explicit Camera(const CameraDesc& d) : position(d.position), width(d.width), height(d.height) {
    forward = (d.look_at - d.position).normalized();
    right = forward.cross(d.up).normalized();
    up = right.cross(forward);
    tan_half = std::tan(0.5 * d.fov_deg * kPi / 180.0);
    aspect = static_cast<double>(d.width) / d.height;
    lens_radius = d.aperture_radius;
    focus = d.focus_distance > 0.0 ? d.focus_distance : (d.look_at - d.position).norm();
  }

  void generate(double fx, double fy, Pcg32& rng, Vec3& o, Vec3& dir) const {
    const double sx = (2.0 * fx / width - 1.0) * tan_half * aspect;
    const double sy = (1.0 - 2.0 * fy / height) * tan_half;
    dir = (forward + sx * right + sy * up).normalized();
    o = position;
    if (lens_radius > 0.0) {
      const Vec3 focal = position + dir * (focus / dir.dot(forward));
      const double r = lens_radius * std::sqrt(rng.uniform());
      const double phi = 2.0 * kPi * rng.uniform();
      o = position + r * std::cos(phi) * right + r * std::sin(phi) * up;
      dir = (focal - o).normalized();
    }
  }
};

/// Everything the integrator reads; built once per render.
struct World {
  std::vector<MaterialDesc> materials;
  std::vector<std::shared_ptr<const Medium>> media;
  std::unique_ptr<Geometry> geometry;
  std::vector<Light> lights;
  std::vector<int> light_of_shape;  ///< light index of an emitting shape, else -1
  Rgb environment{0, 0, 0};
  int environment_light = -1;
  std::shared_ptr<const EnvironmentMap> environment_map;  ///< image environment (replaces the constant)
  bool any_null = false;
  double eps = 1e-5;  ///< ray offsets, relative to coordinates and scene size (float hit points)
  double extent = 1.0;
  IntegratorDesc settings;
};

/// Per-thread state: ray counts and each medium's scratch (trackers, accessors).
struct PathCounters {
  std::uint64_t rays = 0;
  std::vector<std::unique_ptr<MediumScratch>> scratch;

  explicit PathCounters(const std::vector<std::shared_ptr<const Medium>>& media) {
    for (const auto& m : media) scratch.push_back(m->make_scratch());
  }
};

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

template <bool kMedia, bool kNonExp>
class Integrator {
 public:
  explicit Integrator(const World& w) : w_(w) {}

  /// Radiance along a camera ray (docs/render.md §1–§3).
  Rgb li(Vec3 o, Vec3 d, Pcg32& rng, PathCounters& counters) const {
    Rgb radiance(0, 0, 0);
    Rgb beta(1, 1, 1);
    int medium = -1;  // the camera sits in vacuum
    Origin origin = Origin::source;
    bool specular = true;  // the previous direction was not sampled by a density (camera, mirror, glass)
    double prev_pdf = 0.0;
    Vec3 prev_point = o;
    double tmin = 0.0;
    int depth = 0;
    int null_crossings = 0;
    const double light_select = w_.lights.empty() ? 0.0 : 1.0 / static_cast<double>(w_.lights.size());

    for (;;) {
      ++counters.rays;
      const std::optional<SurfaceHit> hit = w_.geometry->intersect(o, d, tmin, std::numeric_limits<double>::infinity());
      const double t_hit = hit ? hit->t : std::numeric_limits<double>::infinity();

      if constexpr (kMedia) {
        if (medium >= 0) {
          const Medium& m = *w_.media[static_cast<std::size_t>(medium)];
          MediumScratch* scratch = counters.scratch[static_cast<std::size_t>(medium)].get();
          const Flight flight = sample_flight<kNonExp>(m, o, d, t_hit, origin, rng, scratch);
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
              const LightSample ls = sample_light(x, rng);
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

      if (!hit) {
        if (w_.environment_light >= 0) {
          const EnvironmentMap* map = w_.environment_map.get();
          const double env_pdf = map != nullptr ? map->pdf(d) : 1.0 / (4.0 * kPi);
          const double mis = specular ? 1.0 : power_heuristic(prev_pdf, light_select * env_pdf);
          radiance += beta * (map != nullptr ? map->radiance(d) : w_.environment) * mis;
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
        o = offset(hit->p, hit->n, d);
        tmin = 0.0;
        continue;
      }

      const MaterialDesc& mat = w_.materials[static_cast<std::size_t>(shape.material)];
      if (++depth > w_.settings.max_depth) break;
      origin = Origin::source;
      const Vec3 n = entering ? hit->n : Vec3(-hit->n);  // faces the incoming side

      if (mat.kind == MaterialKind::diffuse) {
        if (!w_.lights.empty()) {
          const LightSample ls = sample_light(hit->p, rng);
          const double cos_i = n.dot(ls.wi);
          if (ls.pdf > 0.0 && cos_i > 0.0 && (ls.le > 0.0).any()) {
            const double tr = shadow(offset(hit->p, hit->n, ls.wi), ls, medium, Origin::source, rng, counters);
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
      o = offset(hit->p, hit->n, d);
      tmin = 0.0;
      if (!roulette(beta, depth, rng)) break;
    }
    return radiance;
  }

 private:
  Vec3 offset(const Vec3& p, const Vec3& n, const Vec3& dir) const {
    const double scale = w_.eps * (w_.extent + p.cwiseAbs().maxCoeff());
    return p + (n.dot(dir) > 0.0 ? scale : -scale) * n;
  }

  bool roulette(Rgb& beta, int depth, Pcg32& rng) const {
    if (depth < w_.settings.rr_depth) return true;
    const double q = std::min(1.0, beta.maxCoeff());
    if (q >= 1.0) return true;
    if (q <= 0.0 || rng.uniform() >= q) return false;
    beta /= q;
    return true;
  }

  LightSample sample_light(const Vec3& x, Pcg32& rng) const {
    LightSample ls;
    const auto count = static_cast<std::uint32_t>(w_.lights.size());
    const Light& light = w_.lights[rng.uniform_below(count)];
    const double select = 1.0 / count;
    switch (light.kind) {
      case Light::Kind::area: {
        const AreaSample a = w_.geometry->sample_area(light.shape, rng);
        const Vec3 to = a.p - x;
        const double dist2 = to.squaredNorm();
        ls.dist = std::sqrt(dist2);
        if (ls.dist == 0.0) return ls;
        ls.wi = to / ls.dist;
        const double cos_l = -a.n.dot(ls.wi);
        if (cos_l <= 0.0) return ls;  // back side does not emit
        const ShapeInfo& s = w_.geometry->shapes()[static_cast<std::size_t>(light.shape)];
        ls.pdf = select * dist2 / (s.area * cos_l);
        ls.le = light.radiance;
        ls.point = a.p;
        ls.margin = w_.eps * (w_.extent + a.p.cwiseAbs().maxCoeff()) + 1e-6 * ls.dist;
        break;
      }
      case Light::Kind::point: {
        const Vec3 to = light.position - x;
        const double dist2 = to.squaredNorm();
        ls.dist = std::sqrt(dist2);
        if (ls.dist == 0.0) return ls;
        ls.wi = to / ls.dist;
        ls.point = light.position;
        ls.le = light.radiance / dist2;
        ls.pdf = select;
        ls.delta = true;
        break;
      }
      case Light::Kind::directional:
        ls.wi = -light.direction;
        ls.dist = std::numeric_limits<double>::infinity();
        ls.le = light.radiance;
        ls.pdf = select;
        ls.delta = true;
        break;
      case Light::Kind::environment: {
        if (w_.environment_map) {
          const double xi1 = rng.uniform();
          const EnvironmentMap::Sample es = w_.environment_map->sample(xi1, rng.uniform());
          if (!(es.pdf > 0.0)) return ls;
          ls.wi = es.wi;
          ls.dist = std::numeric_limits<double>::infinity();
          ls.le = es.radiance;
          ls.pdf = select * es.pdf;
          break;
        }
        const double z = 1.0 - 2.0 * rng.uniform();
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = 2.0 * kPi * rng.uniform();
        ls.wi = Vec3(r * std::cos(phi), r * std::sin(phi), z);
        ls.dist = std::numeric_limits<double>::infinity();
        ls.le = light.radiance;
        ls.pdf = select / (4.0 * kPi);
        break;
      }
    }
    return ls;
  }

  /// Transmittance of a shadow ray from x (in `medium`, leaving a vertex of kind `origin`) over
  /// distance `dist`: null boundaries are crossed (each restarting the flight as from a source),
  /// anything else blocks.
  double shadow(Vec3 x, const LightSample& ls, int medium, Origin origin, Pcg32& rng, PathCounters& counters) const {
    const Vec3& wi = ls.wi;
    // Measured from the shadow ray's own (offset) origin, so it cannot reach the light's surface.
    const double dist = std::isfinite(ls.dist) ? std::max(0.0, (ls.point - x).norm() - ls.margin) : ls.dist;
    double tmin = 0.0;
    if constexpr (!kMedia) {
      if (!w_.any_null) {
        ++counters.rays;
        return w_.geometry->occluded(x, wi, tmin, dist) ? 0.0 : 1.0;
      }
    }
    double tr = 1.0;
    double remaining = dist;
    for (int crossing = 0; crossing <= kMaxNullCrossings; ++crossing) {
      ++counters.rays;
      const std::optional<SurfaceHit> hit = w_.geometry->intersect(x, wi, tmin, remaining);
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
      if constexpr (kMedia) {
        medium = hit->n.dot(wi) < 0.0 ? s.interior : s.exterior;
        origin = Origin::source;
      }
      x = offset(hit->p, hit->n, wi);
      remaining -= hit->t;
      tmin = 0.0;
      if (!(remaining > 0.0)) return tr;
    }
    return 0.0;
  }

  const World& w_;
};

World build_world(const SceneDesc& scene) {
  World w;
  w.settings = scene.integrator;
  std::map<std::string, int> material_index;
  for (const auto& [name, m] : scene.materials) {
    material_index[name] = static_cast<int>(w.materials.size());
    w.materials.push_back(m);
    if (m.kind == MaterialKind::null) w.any_null = true;
  }
  std::map<std::string, int> medium_index;
  for (const auto& [name, m] : scene.media) {
    medium_index[name] = static_cast<int>(w.media.size());
    // Built by parse_scene (read once); a description made in code is built here.
    w.media.push_back(m.loaded ? m.loaded : make_medium(m, "medium '" + name + "'"));
  }
  w.geometry = std::make_unique<Geometry>(scene, material_index, medium_index);
  w.extent = w.geometry->extent();
  const auto& shapes = w.geometry->shapes();
  w.light_of_shape.assign(shapes.size(), -1);
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    if ((shapes[i].emission > 0.0).any()) {
      w.light_of_shape[i] = static_cast<int>(w.lights.size());
      Light light;
      light.kind = Light::Kind::area;
      light.shape = static_cast<int>(i);
      light.radiance = shapes[i].emission;
      w.lights.push_back(light);
    }
  }
  for (const auto& l : scene.lights) {
    switch (l.kind) {
      case LightKind::point: {
        Light light;
        light.kind = Light::Kind::point;
        light.position = l.position;
        light.radiance = l.intensity;
        w.lights.push_back(light);
        break;
      }
      case LightKind::directional: {
        Light light;
        light.kind = Light::Kind::directional;
        light.direction = l.direction.normalized();
        light.radiance = l.intensity;
        w.lights.push_back(light);
        break;
      }
      case LightKind::environment:
        if (!l.image.empty()) {
          w.environment_map =
              l.loaded ? l.loaded : std::make_shared<const EnvironmentMap>(load_environment(l.image, l.scale));
          w.environment = Rgb(1, 1, 1);  // marks the light as present; radiance comes from the map
        } else {
          w.environment += l.intensity;
        }
        break;
    }
  }
  if ((w.environment > 0.0).any()) {
    w.environment_light = static_cast<int>(w.lights.size());
    Light light;
    light.kind = Light::Kind::environment;
    light.radiance = w.environment;
    w.lights.push_back(light);
  }
  return w;
}

template <bool kMedia, bool kNonExp>
void render_pass(const World& world, const Camera& camera, std::uint64_t seed, int s_begin, int s_end,
                 std::vector<double>& sum, std::vector<double>& sum2, std::atomic<std::uint64_t>& rays,
                 std::atomic<std::uint64_t>& invalid, std::atomic<std::uint64_t>& cells,
                 std::atomic<std::uint64_t>& lookups, ProgressTask& task) {
  const Integrator<kMedia, kNonExp> integrator(world);
  constexpr int kTile = 16;
  const int tiles_x = (camera.width + kTile - 1) / kTile;
  const int tiles_y = (camera.height + kTile - 1) / kTile;
  tbb::enumerable_thread_specific<PathCounters> thread_counters(world.media);
  // Tiles are the work units, over threads and MPI ranks (dist::run_units). A run without a store
  // gives tile t to rank t mod N in every pass, so each rank keeps the running sums of its own
  // tiles in `sum`/`sum2` across passes and every pixel accumulates its samples in order, as in
  // one process. A tile's result carries its ray counts and, from ranks other than 0, its sums
  // after this pass (rank 0's own tiles are already in place).
  dist::UnitsOptions how;
  how.progress = &task;
  how.name = [&](std::size_t t) {
    return fmt::format("render tile {} (x {}, y {}), samples {}..{}", t, (t % tiles_x) * kTile, (t / tiles_x) * kTile,
                       s_begin, s_end - 1);
  };
  const auto tile_pixels = [&](std::size_t t, auto&& f) {
    const int tx = static_cast<int>(t % static_cast<std::size_t>(tiles_x));
    const int ty = static_cast<int>(t / static_cast<std::size_t>(tiles_x));
    for (int y = ty * kTile; y < std::min(camera.height, (ty + 1) * kTile); ++y) {
      for (int x = tx * kTile; x < std::min(camera.width, (tx + 1) * kTile); ++x) {
        f(x, y, static_cast<std::size_t>(y) * camera.width + x);
      }
    }
  };
  const std::vector<dist::Bytes> tiles = dist::run_units(
      static_cast<std::size_t>(tiles_x) * tiles_y,
      [&](std::size_t t) {
        PathCounters& counters = thread_counters.local();
        const std::uint64_t rays_before = counters.rays;
        const auto work_of = [&] {
          MediumWork total;
          for (std::size_t m = 0; m < world.media.size(); ++m) {
            const MediumWork w = world.media[m]->work(counters.scratch[m].get());
            total.cells += w.cells;
            total.lookups += w.lookups;
          }
          return total;
        };
        const MediumWork work_before = work_of();
        std::uint64_t bad = 0;
        tile_pixels(t, [&](int x, int y, std::size_t pixel) {
          for (int s = s_begin; s < s_end; ++s) {
            // One stream per (sample, pixel): the image is the same for any tiling or thread count.
            Pcg32 rng = stream_for(seed, (static_cast<std::uint64_t>(s) << 32U) | pixel);
            Vec3 o;
            Vec3 d;
            camera.generate(x + rng.uniform(), y + rng.uniform(), rng, o, d);
            Rgb value = integrator.li(o, d, rng, counters);
            if (!value.isFinite().all()) {
              value.setZero();
              ++bad;
            }
            for (int c = 0; c < 3; ++c) {
              sum[pixel * 3 + c] += value[c];
              sum2[pixel * 3 + c] += value[c] * value[c];
            }
          }
        });
        const MediumWork work_after = work_of();
        std::vector<double> out{static_cast<double>(counters.rays - rays_before), static_cast<double>(bad),
                                static_cast<double>(work_after.cells - work_before.cells),
                                static_cast<double>(work_after.lookups - work_before.lookups)};
        if (!dist::is_root()) {
          tile_pixels(t, [&](int, int, std::size_t pixel) {
            out.insert(out.end(), sum.begin() + static_cast<std::ptrdiff_t>(pixel * 3),
                       sum.begin() + static_cast<std::ptrdiff_t>(pixel * 3 + 3));
            out.insert(out.end(), sum2.begin() + static_cast<std::ptrdiff_t>(pixel * 3),
                       sum2.begin() + static_cast<std::ptrdiff_t>(pixel * 3 + 3));
          });
        }
        dist::Bytes b(out.size() * sizeof(double));
        std::memcpy(b.data(), out.data(), b.size());
        return b;
      },
      how);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    std::vector<double> in(tiles[t].size() / sizeof(double));
    std::memcpy(in.data(), tiles[t].data(), in.size() * sizeof(double));
    rays += static_cast<std::uint64_t>(in[0]);
    invalid += static_cast<std::uint64_t>(in[1]);
    cells += static_cast<std::uint64_t>(in[2]);
    lookups += static_cast<std::uint64_t>(in[3]);
    if (in.size() == 4) continue;  // rank 0's own tile
    std::size_t k = 4;
    tile_pixels(t, [&](int, int, std::size_t pixel) {
      std::copy(in.begin() + static_cast<std::ptrdiff_t>(k), in.begin() + static_cast<std::ptrdiff_t>(k + 3),
                sum.begin() + static_cast<std::ptrdiff_t>(pixel * 3));
      std::copy(in.begin() + static_cast<std::ptrdiff_t>(k + 3), in.begin() + static_cast<std::ptrdiff_t>(k + 6),
                sum2.begin() + static_cast<std::ptrdiff_t>(pixel * 3));
      k += 6;
    });
  }
}

Image make_image(int width, int height, int n, const std::vector<double>& sum, const std::vector<double>& sum2) {
  Image image;
  image.width = width;
  image.height = height;
  image.spp = n;
  image.rgb.resize(sum.size());
  image.variance.resize(sum.size());
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double mean = sum[i] / n;
    const double var = n > 1 ? std::max(0.0, (sum2[i] - n * mean * mean) / (n - 1)) : 0.0;
    image.rgb[i] = static_cast<float>(mean);
    image.variance[i] = static_cast<float>(var / n);
  }
  return image;
}

}  // namespace

Features scene_features(const SceneDesc& scene) {
  Features f;
  for (const auto& s : scene.shapes) {
    if ((s.emission > 0.0).any()) f.area_lights = true;
    if (!s.interior.empty() || !s.exterior.empty()) f.media = true;
    if (s.kind == ShapeKind::curves) f.curves = true;
  }
  for (const auto& l : scene.lights)
    if (l.kind == LightKind::environment && ((l.intensity > 0.0).any() || !l.image.empty())) {
      f.environment = true;
      if (!l.image.empty()) f.environment_image = true;
    }
  if (f.media) {
    // Asked from the media themselves (built once by parse_scene; built here for a description
    // made in code).
    for (const auto& [name, desc] : scene.media) {
      const std::shared_ptr<const Medium> m = desc.loaded ? desc.loaded : make_medium(desc, "medium '" + name + "'");
      const MediumTraits t = m->traits();
      if (!t.exponential) f.general_media = true;
      if (t.heterogeneous) f.heterogeneous = true;
      if (t.non_reciprocal) f.non_reciprocal = true;
      f.media_described.push_back("medium '" + name + "': " + t.describe());
    }
  }
  return f;
}

RenderResult render(const SceneDesc& scene, const RenderOptions& options, ProgressSink& progress) {
  const auto start = std::chrono::steady_clock::now();
  const World world = build_world(scene);
  const Camera camera(scene.camera);
  const int spp = options.spp.value_or(scene.integrator.spp);
  if (spp < 1) fail("spp must be >= 1, got {}", spp);
  const std::uint64_t seed = options.seed.value_or(scene.integrator.seed);
  if (options.time_budget_seconds < 0.0 || !std::isfinite(options.time_budget_seconds))
    fail("time budget must be finite and >= 0, got {}", options.time_budget_seconds);

  RenderResult result;
  result.stats.features = scene_features(scene);
  const Features& f = result.stats.features;
  const std::size_t n = static_cast<std::size_t>(camera.width) * camera.height * 3;
  std::vector<double> sum(n, 0.0);
  std::vector<double> sum2(n, 0.0);
  std::atomic<std::uint64_t> rays{0};
  std::atomic<std::uint64_t> invalid{0};
  std::atomic<std::uint64_t> cells{0};
  std::atomic<std::uint64_t> lookups{0};

  const bool passes = options.time_budget_seconds > 0.0 || static_cast<bool>(options.on_pass);
  const int per_pass = passes ? std::max(1, options.spp_per_pass) : spp;
  const int tiles = ((camera.width + 15) / 16) * ((camera.height + 15) / 16);
  const int pass_count = (spp + per_pass - 1) / per_pass;
  ProgressTask task(progress, "render", static_cast<std::uint64_t>(tiles) * pass_count);
  IntegratorChoice choice = options.integrator;
  const IntegratorChoice needed = !f.media          ? IntegratorChoice::surfaces
                                  : f.general_media ? IntegratorChoice::general
                                                    : IntegratorChoice::exponential;
  if (choice == IntegratorChoice::automatic) choice = needed;
  if (static_cast<int>(choice) < static_cast<int>(needed))
    fail("the scene needs a more general integrator than the one requested");
  result.stats.integrator = choice == IntegratorChoice::surfaces      ? "surfaces"
                            : choice == IntegratorChoice::exponential ? "volpath<exponential>"
                                                                      : "volpath<general>";

  int done = 0;
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  while (done < spp) {
    const int end = std::min(spp, done + per_pass);
    if (choice == IntegratorChoice::surfaces) {
      render_pass<false, false>(world, camera, seed, done, end, sum, sum2, rays, invalid, cells, lookups, task);
    } else if (choice == IntegratorChoice::exponential) {
      render_pass<true, false>(world, camera, seed, done, end, sum, sum2, rays, invalid, cells, lookups, task);
    } else {
      render_pass<true, true>(world, camera, seed, done, end, sum, sum2, rays, invalid, cells, lookups, task);
    }
    done = end;
    // Rank 0 holds the whole image after each pass (render_pass) and decides for every rank
    // whether the time budget is spent.
    if (options.on_pass && dist::is_root())
      options.on_pass(done, seconds(), make_image(camera.width, camera.height, done, sum, sum2));
    if (options.time_budget_seconds > 0.0 && dist::root_decides(seconds() >= options.time_budget_seconds)) break;
  }
  result.image = make_image(camera.width, camera.height, done, sum, sum2);
  result.stats.spp = done;
  result.stats.seconds = seconds();
  result.stats.paths = static_cast<std::uint64_t>(done) * camera.width * camera.height;
  result.stats.rays = rays.load();
  result.stats.invalid_samples = invalid.load();
  result.stats.medium_cells = cells.load();
  result.stats.medium_lookups = lookups.load();
  return result;
}

}  // namespace weft::render
