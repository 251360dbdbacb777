// The scene writer (scene.h: scene_to_json), every field in canonical form (docs/scene-format.md).
#include "weft/render/scene.h"

#include <string>

#include <nlohmann/json.hpp>

#include "weft/render/scene_choices_impl.h"
#include "weft/transmittance/law_json.h"

namespace weft::render {

using nlohmann::json;

namespace {

json to_json(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }
json to_json(const Rgb& c) { return json::array({c[0], c[1], c[2]}); }

}  // namespace

std::string scene_to_json(const SceneDesc& scene) {
  json root;
  const CameraDesc& c = scene.camera;
  root["camera"] = {{"type", "perspective"},
                    {"position", to_json(c.position)},
                    {"look_at", to_json(c.look_at)},
                    {"up", to_json(c.up)},
                    {"fov", c.fov_deg},
                    {"aperture_radius", c.aperture_radius},
                    {"focus_distance", c.focus_distance},
                    {"width", c.width},
                    {"height", c.height}};
  const IntegratorDesc& d = scene.integrator;
  root["integrator"] = {
      {"type", "volpath"}, {"spp", d.spp}, {"max_depth", d.max_depth}, {"rr_depth", d.rr_depth}, {"seed", d.seed}};
  json materials = json::object();
  for (const auto& [name, m] : scene.materials) {
    json j = {{"type", choice_name(m.kind, kMaterialKinds)}};
    if (m.kind != MaterialKind::null) j["albedo"] = to_json(m.albedo);
    if (m.kind == MaterialKind::dielectric) j["ior"] = m.ior;
    materials[name] = j;
  }
  root["materials"] = materials;
  json media = json::object();
  for (const auto& [name, m] : scene.media) {
    if (m.kind == MediumKind::local_gamma) {
      media[name] = {{"type", choice_name(m.kind, kMediumKinds)},
                     {"fields", m.file},
                     {"sigma", m.sigma},
                     {"memory", choice_name(m.memory, memory_rules())},
                     {"albedo", to_json(m.albedo)},
                     {"g", m.g}};
      continue;
    }
    json j = {{"type", choice_name(m.kind, kMediumKinds)},
              {"law", transmittance::law_to_json(m.law)},
              {"mode", choice_name(m.mode, kModes)},
              {"given", choice_name(m.given, kOrigins)},
              {"albedo", to_json(m.albedo)},
              {"g", m.g}};
    if (m.mode == transmittance::PairMode::explicit_) j["scatterer_law"] = transmittance::law_to_json(m.scatterer_law);
    if (m.kind == MediumKind::grid) {
      j["file"] = m.file;
      if (m.axis_grids.empty()) {
        j["grid"] = m.grid_name;
      } else {
        j["axis_grids"] = m.axis_grids;
      }
      j["values"] = m.concentration ? "concentration" : "extinction";
      if (m.concentration) j["sigma"] = m.sigma;
      j["tracking"] = choice_name(m.tracking, kTrackings);
    }
    media[name] = j;
  }
  root["media"] = media;
  json shapes = json::array();
  for (const auto& s : scene.shapes) {
    json j = {{"type", choice_name(s.kind, kShapeKinds)}};
    switch (s.kind) {
      case ShapeKind::sphere:
        j["center"] = to_json(s.center);
        j["radius"] = s.radius;
        break;
      case ShapeKind::box:
        j["min"] = to_json(s.min);
        j["max"] = to_json(s.max);
        break;
      case ShapeKind::rectangle:
        j["corner"] = to_json(s.corner);
        j["edge_u"] = to_json(s.edge_u);
        j["edge_v"] = to_json(s.edge_v);
        break;
      case ShapeKind::mesh:
        j["file"] = s.file;
        j["scale"] = s.scale;
        j["translate"] = to_json(s.translate);
        break;
      case ShapeKind::curves:
        j["file"] = s.file;
        j["radius"] = s.radius;
        j["scale"] = s.scale;
        j["translate"] = to_json(s.translate);
        break;
    }
    if (!s.material.empty()) j["material"] = s.material;
    if (!s.interior.empty()) j["interior"] = s.interior;
    if (!s.exterior.empty()) j["exterior"] = s.exterior;
    if ((s.emission != 0.0).any()) j["emission"] = to_json(s.emission);
    shapes.push_back(j);
  }
  root["shapes"] = shapes;
  json lights = json::array();
  for (const auto& l : scene.lights) {
    json j = {{"type", choice_name(l.kind, kLightKinds)}};
    switch (l.kind) {
      case LightKind::point:
        j["position"] = to_json(l.position);
        j["intensity"] = to_json(l.intensity);
        break;
      case LightKind::directional:
        j["direction"] = to_json(l.direction);
        j["irradiance"] = to_json(l.intensity);
        break;
      case LightKind::environment:
        if (l.image.empty()) {
          j["radiance"] = to_json(l.intensity);
        } else {
          j["image"] = l.image;
          j["scale"] = l.scale;
        }
        break;
    }
    lights.push_back(j);
  }
  root["lights"] = lights;
  return root.dump(2) + "\n";
}

}  // namespace weft::render
