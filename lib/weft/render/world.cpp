#include "weft/render/world.h"

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "weft/core/error.h"

namespace weft::render {

namespace {

/// What the scene uses; media are asked about themselves (their traits), so the integrator's
/// specialisation never depends on which kind of medium it holds (docs/render.md §1).
Features features_of(const SceneDesc& scene, const World& w) {
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
    for (std::size_t i = 0; i < w.media.size(); ++i) {
      const MediumTraits t = w.media[i]->traits();
      if (!t.exponential) f.general_media = true;
      if (t.heterogeneous) f.heterogeneous = true;
      if (t.non_reciprocal) f.non_reciprocal = true;
      f.media_described.push_back("medium '" + w.medium_names[i] + "': " + t.describe());
    }
  }
  return f;
}

/// What a probe from the camera found: the medium and the boundary that decided it (-1: none).
struct Probe {
  int medium = -1;
  int shape = -1;
  bool inside = false;
};

/// Follows a ray from `o` along `d` to the first surface that changes a path's medium (a null or
/// a dielectric material: integrator.cpp switches the medium there and nowhere else; opaque
/// surfaces and emitters are passed): reached from inside (its back face) the camera is in that
/// shape's interior, from outside in its exterior; no such surface: vacuum.
Probe probe_medium(const World& w, Vec3 o, const Vec3& d) {
  constexpr int kMaxSurfaces = 100000;  // a ray that keeps hitting opaque surfaces gives up: vacuum
  for (int i = 0; i < kMaxSurfaces; ++i) {
    const std::optional<SurfaceHit> hit = w.geometry->intersect(o, d, 0.0, std::numeric_limits<double>::infinity());
    if (!hit) return {};
    const ShapeInfo& s = w.geometry->shapes()[static_cast<std::size_t>(hit->shape)];
    const bool boundary =
        s.null_material ||
        (s.material >= 0 && w.materials[static_cast<std::size_t>(s.material)].kind == MaterialKind::dielectric);
    const bool inside = hit->n.dot(d) > 0.0;
    if (boundary) return {inside ? s.interior : s.exterior, hit->shape, inside};
    o = hit->p + w.geometry->spawn_offset(hit->p, hit->shape) * d;  // past it, as integrator.cpp's offset
  }
  return {};
}

/// The camera's medium (docs/scene-format.md "The camera's medium"): probes from the camera
/// position along the view direction and the six axis directions. A probe that meets no boundary
/// says nothing (the medium on its way to infinity is whatever the camera is in); those that meet
/// one must agree, else the boundaries around the camera are open or contradict each other and
/// no medium is right: an error naming what two probes found, never a silent guess.
int camera_medium(const SceneDesc& scene, const World& w) {
  const Vec3 view = (scene.camera.look_at - scene.camera.position).normalized();
  const std::pair<const char*, Vec3> directions[] = {
      {"the view direction", view}, {"+x", Vec3::UnitX()}, {"-x", -Vec3::UnitX()}, {"+y", Vec3::UnitY()},
      {"-y", -Vec3::UnitY()},       {"+z", Vec3::UnitZ()}, {"-z", -Vec3::UnitZ()}};
  const auto said = [&](const char* name, const Probe& p) {
    const std::string medium =
        p.medium < 0 ? "vacuum" : "medium '" + w.medium_names[static_cast<std::size_t>(p.medium)] + "'";
    return fmt::format("a ray along {} meets shapes[{}] from {} ({})", name, p.shape, p.inside ? "inside" : "outside",
                       medium);
  };
  std::optional<std::pair<const char*, Probe>> decided;
  for (const auto& [name, d] : directions) {
    const Probe p = probe_medium(w, scene.camera.position, d);
    if (p.shape < 0) continue;
    if (!decided) {
      decided.emplace(name, p);
    } else if (p.medium != decided->second.medium) {
      fail("{}: camera: its medium is ambiguous: {}, {}; close the boundaries around the camera or move it",
           scene.source, said(decided->first, decided->second), said(name, p));
    }
  }
  return decided ? decided->second.medium : -1;
}

}  // namespace

std::shared_ptr<const Medium> build_medium(const SceneDesc& scene, const std::string& name) {
  const auto it = scene.media.find(name);
  if (it == scene.media.end()) fail("{}: no medium '{}'", scene.source, name);
  return make_medium(it->second, scene.source + ": media." + name);
}

World build_world(const SceneDesc& scene) {
  World w;
  w.source = scene.source;
  w.camera = scene.camera;
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
    w.media.push_back(build_medium(scene, name));
    w.medium_names.push_back(name);
  }
  w.geometry = std::make_unique<Geometry>(scene, material_index, medium_index);
  if (!w.geometry->shapes().empty()) {
    // The camera's rays start within its lens: the one table of limits (geometry.h); a scene
    // without shapes traces nothing.
    const double at = w.geometry->reach(scene.camera.position, scene.camera.position);
    try {
      w.geometry->require_traceable(at, Traced::camera, "camera.position reaches");
      w.geometry->require_traceable(at + scene.camera.aperture_radius, Traced::camera,
                                    "camera.position plus camera.aperture_radius reaches");
    } catch (const Error& e) {
      fail("{}: {}", scene.source, e.what());
    }
  }
  w.lights = build_lights(scene, *w.geometry);
  w.features = features_of(scene, w);
  if (w.features.media) w.camera_medium = camera_medium(scene, w);
  return w;
}

}  // namespace weft::render
