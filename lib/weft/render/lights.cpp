#include "weft/render/lights.h"

#include <algorithm>

#include <cmath>
#include <limits>
#include <numbers>

#include "weft/core/error.h"

namespace weft::render {

LightSample LightSet::sample(const Vec3& x, const Geometry& geometry, Pcg32& rng) const {
  constexpr double kPi = std::numbers::pi;
  LightSample ls;
  const auto count = static_cast<std::uint32_t>(lights.size());
  const Light& light = lights[rng.uniform_below(count)];
  const double select = 1.0 / count;
  switch (light.kind) {
    case Light::Kind::area: {
      const AreaSample a = geometry.sample_area(light.shape, rng);
      const Vec3 to = a.p - x;
      const double dist2 = to.squaredNorm();
      ls.dist = std::sqrt(dist2);
      if (ls.dist == 0.0) return ls;
      ls.wi = to / ls.dist;
      const double cos_l = -a.n.dot(ls.wi);
      if (cos_l <= 0.0) return ls;  // back side does not emit
      const ShapeInfo& s = geometry.shapes()[static_cast<std::size_t>(light.shape)];
      ls.pdf = select * dist2 / (s.area * cos_l);
      ls.le = light.radiance;
      ls.point = a.p;
      ls.margin = geometry.spawn_offset(a.p, light.shape) + 1e-6 * ls.dist;
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
      if (environment_map) {
        const double xi1 = rng.uniform();
        const EnvironmentMap::Sample es = environment_map->sample(xi1, rng.uniform());
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

LightSet build_lights(const SceneDesc& scene, const Geometry& geometry) {
  LightSet w;
  const auto& shapes = geometry.shapes();
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
  for (std::size_t index = 0; index < scene.lights.size(); ++index) {
    const LightDesc& l = scene.lights[index];
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
          try {
            w.environment_map = std::make_shared<const EnvironmentMap>(load_environment(l.image, l.scale));
          } catch (const Error& e) {
            fail("{}: lights[{}]: {}", scene.source, index, e.what());
          }
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

bool LightSet::emits() const {
  return std::any_of(lights.begin(), lights.end(), [&](const Light& l) {
    if (l.kind == Light::Kind::environment && environment_map) return environment_map->emits();
    return (l.radiance > 0.0).any();
  });
}

}  // namespace weft::render
