#include "weft/render/scene.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/core/file_kind.h"
#include "weft/core/json_input.h"
#include "weft/core/names.h"
#include "weft/core/paths.h"
#include "weft/curves/curve_io.h"
#include "weft/render/environment.h"
#include "weft/render/frame.h"
#include "weft/render/medium.h"
#include "weft/render/mesh.h"
#include "weft/render/phase.h"
#include "weft/render/render.h"
#include "weft/render/scene_choices_impl.h"
#include "weft/transmittance/law_json.h"

namespace weft::render {

void shrink_film(CameraDesc& camera, int longest) {
  const double f = static_cast<double>(longest) / std::max(camera.width, camera.height);
  camera.width = std::max(1, static_cast<int>(std::lround(camera.width * f)));
  camera.height = std::max(1, static_cast<int>(std::lround(camera.height * f)));
}

using nlohmann::json;

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// A file a scene names, resolved once for every kind (docs/scene-format.md) by resolve_beside:
/// relative to the scene file's folder, kept absolute (scene_to_json writes a scene that loads
/// wherever it is saved; re-reading it, as the image study's candidates do, does not join the
/// folder twice). A missing file is named with that absolute path.
std::string resolve_file(const std::string& name, const std::filesystem::path& base_dir, const std::string& where,
                         const char* what) {
  std::string p = resolve_beside(name, base_dir);
  if (what != nullptr && !std::filesystem::exists(p)) fail("{}: {} '{}' does not exist", where, what, p);
  return p;
}

/// A JSON object being read: every key must be consumed or named as allowed, so a misspelt
/// key is an error with a suggestion instead of being silently ignored.
class Reader {
 public:
  Reader(const json& j, std::string where) : j_(j), where_(std::move(where)) {
    if (!j_.is_object()) fail("{}: expected a JSON object, got {}", where_, j_.type_name());
  }

  [[nodiscard]] const std::string& where() const { return where_; }
  [[nodiscard]] bool has(const std::string& key) {
    known_.insert(key);
    return j_.contains(key);
  }
  const json& at(const std::string& key) {
    known_.insert(key);
    if (!j_.contains(key)) fail("{}: missing required key '{}'", where_, key);
    return j_.at(key);
  }

  double number(const std::string& key, double fallback) {
    if (!has(key)) return fallback;
    return number_value(j_.at(key), key);
  }
  double number(const std::string& key) { return number_value(at(key), key); }
  double positive(const std::string& key, double fallback) {
    const double v = number(key, fallback);
    if (!(v > 0.0)) fail("{}: '{}' must be > 0, got {}", where_, key, v);
    return v;
  }
  double non_negative(const std::string& key, double fallback) {
    const double v = number(key, fallback);
    if (!(v >= 0.0)) fail("{}: '{}' must be >= 0, got {}", where_, key, v);
    return v;
  }
  int integer(const std::string& key, int fallback, int lo, int hi) {
    if (!has(key)) return fallback;
    const json& v = j_.at(key);
    if (!v.is_number_integer()) fail("{}: '{}' must be an integer, got {}", where_, key, v.dump());
    const auto x = v.get<std::int64_t>();
    if (x < lo || x > hi) fail("{}: '{}' must be in [{}, {}], got {}", where_, key, lo, hi, x);
    return static_cast<int>(x);
  }
  /// A file name that must be given: missing, null and "" are refused, each said as what it is.
  std::string required_file(const std::string& key, const char* what) {
    std::string name = string(key, "");
    if (!name.empty()) return name;
    if (!j_.contains(key)) fail("{}: missing required key '{}' ({})", where_, key, what);
    fail("{}: '{}' is {} (give {})", where_, key, j_.at(key).is_null() ? "null" : "empty", what);
  }
  std::string string(const std::string& key, const std::string& fallback) {
    if (!has(key)) return fallback;
    const json& v = j_.at(key);
    if (v.is_null()) return "";
    if (!v.is_string()) fail("{}: '{}' must be a string, got {}", where_, key, v.dump());
    return v.get<std::string>();
  }
  Vec3 vec3(const std::string& key, const Vec3& fallback) {
    if (!has(key)) return fallback;
    const json& v = j_.at(key);
    if (!v.is_array() || v.size() != 3) fail("{}: '{}' must be an array of 3 numbers, got {}", where_, key, v.dump());
    return {number_value(v[0], key), number_value(v[1], key), number_value(v[2], key)};
  }
  /// A colour: one number (grey) or three; each finite and >= 0.
  Rgb rgb(const std::string& key, const Rgb& fallback) {
    if (!has(key)) return fallback;
    const json& v = j_.at(key);
    Rgb c;
    if (v.is_number()) {
      c.setConstant(number_value(v, key));
    } else if (v.is_array() && v.size() == 3) {
      c = Rgb(number_value(v[0], key), number_value(v[1], key), number_value(v[2], key));
    } else {
      fail("{}: '{}' must be a number or an array of 3 numbers, got {}", where_, key, v.dump());
    }
    if ((c < 0.0).any()) fail("{}: '{}' must be >= 0, got {}", where_, key, v.dump());
    return c;
  }
  /// An albedo: a colour of at most 1 in every channel. Every material that has one (diffuse
  /// reflectance, mirror and dielectric tint) and every medium (single-scattering albedo Λ)
  /// multiplies the path's throughput by it at each bounce, so above 1 it creates energy
  /// (docs/scene-format.md).
  Rgb albedo(const Rgb& fallback) {
    Rgb c = rgb("albedo", fallback);
    if ((c > 1.0).any()) fail("{}: 'albedo' must be <= 1 to conserve energy, got {}", where_, j_.at("albedo").dump());
    return c;
  }

  /// Throws for the first key that nothing read, naming the closest known key.
  void finish() const {
    for (const auto& [key, value] : j_.items()) {
      if (known_.count(key) == 0) {
        const std::vector<std::string> names(known_.begin(), known_.end());
        fail("{}: unknown key '{}' (did you mean '{}'?)", where_, key, closest_name(key, names));
      }
    }
  }

 private:
  double number_value(const json& v, const std::string& key) const {
    if (!v.is_number()) fail("{}: '{}' must be a number, got {}", where_, key, v.dump());
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail("{}: '{}' must be finite, got {}", where_, key, x);
    return x;
  }

  const json& j_;
  std::string where_;
  std::set<std::string> known_;
};

template <typename Enum>
Enum parse_choice(const std::string& where, const std::string& what, const std::string& value,
                  const std::vector<std::pair<std::string, Enum>>& choices) {
  std::vector<std::string> names;
  for (const auto& [name, e] : choices) {
    if (name == value) return e;
    names.push_back(name);
  }
  // A shape or light has no default type: one left out is said as missing, not as "unknown ''".
  if (value.empty()) fail("{}: no '{}' ({}: one of {})", where, "type", what, join(names));
  fail("{}: unknown {} '{}' (did you mean '{}'? known: {})", where, what, value, closest_name(value, names),
       join(names));
}

CameraDesc parse_camera(const json& j, const std::string& where) {
  Reader r(j, where);
  CameraDesc c;
  const std::string type = r.string("type", "perspective");
  if (type != "perspective") fail("{}: unknown camera type '{}' (did you mean 'perspective'?)", where, type);
  c.position = r.vec3("position", c.position);
  c.look_at = r.vec3("look_at", c.look_at);
  c.up = r.vec3("up", c.up);
  c.fov_deg = r.positive("fov", c.fov_deg);
  if (c.fov_deg >= 180.0) fail("{}: 'fov' must be < 180 degrees, got {}", where, c.fov_deg);
  c.aperture_radius = r.non_negative("aperture_radius", c.aperture_radius);
  c.focus_distance = r.non_negative("focus_distance", c.focus_distance);
  c.width = r.integer("width", c.width, 1, 16384);
  c.height = r.integer("height", c.height, 1, 16384);
  r.finish();
  // Directions by unit_vector (render/frame.h): a tiny but non-zero vector is a direction.
  if ((c.look_at - c.position).isZero(0.0)) fail("{}: 'look_at' equals 'position'", where);
  if (unit_vector(c.up).isZero(0.0)) fail("{}: 'up' must not be zero", where);
  // The roll comes from up × view: within 1e-6 rad of parallel (sin of the angle between the unit
  // vectors), that cross product is rounding, and the image's orientation with it. An `up` written
  // as the view direction itself (look_at − position) differs from it by rounding only.
  if (const double sine = unit_vector(c.look_at - c.position).cross(unit_vector(c.up)).norm(); !(sine >= 1e-6))
    fail(
        "{}: 'up' is parallel to the view direction (the angle between them is {:.3g} rad, under 1e-6: the "
        "image's roll would be set by rounding)",
        where, std::asin(std::min(1.0, sine)));
  return c;
}

IntegratorDesc parse_integrator(const json& j, const std::string& where) {
  Reader r(j, where);
  IntegratorDesc d;
  const std::string type = r.string("type", "volpath");
  if (type != "volpath") fail("{}: unknown integrator type '{}' (did you mean 'volpath'?)", where, type);
  d.spp = r.integer("spp", d.spp, 1, kMaxSpp);
  d.max_depth = r.integer("max_depth", d.max_depth, 1, 100000);
  d.rr_depth = r.integer("rr_depth", d.rr_depth, 0, 100000);
  if (r.has("seed")) {
    const json& s = r.at("seed");
    if (!s.is_number_unsigned()) fail("{}: 'seed' must be a non-negative integer, got {}", where, s.dump());
    d.seed = s.get<std::uint64_t>();
  }
  r.finish();
  return d;
}

MaterialDesc parse_material(const json& j, const std::string& where) {
  Reader r(j, where);
  MaterialDesc m;
  m.kind = parse_choice(where, "material type", r.string("type", "diffuse"), kMaterialKinds);
  if (m.kind != MaterialKind::null) m.albedo = r.albedo(m.kind == MaterialKind::diffuse ? m.albedo : Rgb(1, 1, 1));
  if (m.kind == MaterialKind::dielectric) m.ior = r.positive("ior", m.ior);
  r.finish();
  return m;
}

MediumDesc parse_medium(const json& j, const std::string& where, const std::filesystem::path& base_dir) {
  Reader r(j, where);
  MediumDesc m;
  m.kind = parse_choice(where, "medium type", r.string("type", "homogeneous"), kMediumKinds);
  if (m.kind == MediumKind::local_gamma) {
    // Its laws come from the fields (per-voxel gamma, reciprocal partner per voxel): no law,
    // mode or given keys, so those are unknown keys here.
    m.file = r.required_file("fields", "the .vdb written by `weft fit --block`");
    m.file = resolve_file(m.file, base_dir, where, "fields file");
    m.sigma = r.positive("sigma", m.sigma);
    m.memory = parse_choice(
        where, "memory rule",
        r.string("memory", std::string(transmittance::memory_rule_name(transmittance::kDefaultMemoryRule))),
        memory_rules());
    m.law = transmittance::LawSpec{};  // no law: the fields carry one gamma law per voxel
    m.albedo = r.albedo(m.albedo);
    m.g = r.number("g", m.g);
    check_phase_g(m.g, where);
    r.finish();
    return m;
  }
  if (m.kind == MediumKind::grid) {
    m.file = r.required_file("file", "the grid's .vdb");
    m.file = resolve_file(m.file, base_dir, where, "grid file");
    m.grid_name = r.string("grid", "");
    if (r.has("axis_grids")) {
      const json& v = r.at("axis_grids");
      if (!v.is_array() || v.size() != 3 ||
          !std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_string(); }))
        fail("{}: 'axis_grids' must be an array of 3 grid names (x, y, z), got {}", where, v.dump());
      if (!m.grid_name.empty()) fail("{}: give 'grid' or 'axis_grids', not both", where);
      for (const json& e : v) m.axis_grids.push_back(e.get<std::string>());
    }
    const std::string values = r.string("values", "concentration");
    if (values != "concentration" && values != "extinction")
      fail("{}: 'values' must be 'concentration' or 'extinction', got '{}'", where, values);
    m.concentration = values == "concentration";
    if (m.concentration) {
      m.sigma = r.non_negative("sigma", m.sigma);
    } else if (j.contains("sigma")) {
      // Extinction values are μ itself (docs/scene-format.md): a σ would have nothing to scale.
      fail(
          "{}: 'sigma' does not apply to \"values\": \"extinction\" (the grid holds the extinction itself, in "
          "1/length): remove 'sigma', or use \"values\": \"concentration\" for a grid of C scaled by sigma",
          where);
    }
    m.tracking = parse_choice(where, "tracking", r.string("tracking", "delta"), kTrackings);
    if (!m.axis_grids.empty() && m.tracking != Tracking::delta)
      fail("{}: 'axis_grids' (a direction-dependent extinction) needs delta tracking", where);
    // The law of a grid medium is in optical depth; exponential with μ = 1 by default.
    m.law = r.has("law") ? transmittance::law_from_json(r.at("law"), where + ".law")
                         : transmittance::LawSpec{"exponential", {{"mu", 1.0}}, "", ""};
  } else {
    m.law = transmittance::law_from_json(r.at("law"), where + ".law");
  }
  // Tables are checked by the law that reads them (make_medium_pair below).
  if (!m.law.table.empty()) m.law.table = resolve_file(m.law.table, base_dir, where, nullptr);
  m.mode = parse_choice(where, "mode", r.string("mode", "reciprocal"), kModes);
  m.given = parse_choice(where, "origin", r.string("given", "source"), kOrigins);
  if (m.mode == transmittance::PairMode::explicit_) {
    m.scatterer_law = transmittance::law_from_json(r.at("scatterer_law"), where + ".scatterer_law");
    if (!m.scatterer_law.table.empty())
      m.scatterer_law.table = resolve_file(m.scatterer_law.table, base_dir, where, nullptr);
  }
  m.albedo = r.albedo(m.albedo);
  m.g = r.number("g", m.g);
  check_phase_g(m.g, where);
  r.finish();
  return m;
}

ShapeDesc parse_shape(const json& j, const std::string& where, const SceneDesc& scene) {
  Reader r(j, where);
  ShapeDesc s;
  s.kind = parse_choice(where, "shape type", r.string("type", ""), kShapeKinds);
  switch (s.kind) {
    case ShapeKind::sphere:
      s.center = r.vec3("center", s.center);
      s.radius = r.positive("radius", s.radius);
      break;
    case ShapeKind::box:
      s.min = r.vec3("min", s.min);
      s.max = r.vec3("max", s.max);
      if (!(s.min.array() < s.max.array()).all()) fail("{}: box 'min' must be < 'max' on every axis", where);
      break;
    case ShapeKind::rectangle:
      s.corner = r.vec3("corner", s.corner);
      s.edge_u = r.vec3("edge_u", s.edge_u);
      s.edge_v = r.vec3("edge_v", s.edge_v);
      if (s.edge_u.cross(s.edge_v).norm() == 0.0) fail("{}: rectangle edges are parallel or zero", where);
      break;
    case ShapeKind::mesh:
    case ShapeKind::curves: {
      s.file =
          r.required_file("file", s.kind == ShapeKind::mesh ? "the mesh's .obj or .ply" : "the curves' .bcc or .obj");
      s.file = resolve_file(s.file, scene.base_dir, where, s.kind == ShapeKind::mesh ? "mesh file" : "curve file");
      if (s.kind == ShapeKind::curves) {
        // Fibre radius in the file's units (scaled with the points); BCC files carry no radii.
        (void)r.at("radius");
        s.radius = r.positive("radius", s.radius);
      }
      s.scale = r.positive("scale", s.scale);
      s.translate = r.vec3("translate", s.translate);
      break;
    }
  }
  s.material = r.string("material", "");
  s.interior = r.string("interior", "");
  s.exterior = r.string("exterior", "");
  s.emission = r.rgb("emission", s.emission);
  r.finish();
  auto check_name = [&](const std::string& name, const auto& table, const char* what) {
    if (name.empty() || table.count(name) != 0) return;
    std::vector<std::string> names;
    names.reserve(table.size());
    for (const auto& [n, v] : table) names.push_back(n);
    if (names.empty()) fail("{}: {} '{}' is not defined (the scene defines none)", where, what, name);
    fail("{}: {} '{}' is not defined (did you mean '{}'?)", where, what, name, closest_name(name, names));
  };
  check_name(s.material, scene.materials, "material");
  check_name(s.interior, scene.media, "medium");
  check_name(s.exterior, scene.media, "medium");
  if (s.material.empty() && (!s.interior.empty() || !s.exterior.empty()))
    fail("{}: a shape that bounds a medium needs a material (use \"null\" for an index-matched boundary)", where);
  if (s.material.empty() && (s.emission == 0.0).all()) fail("{}: a shape needs a material or an emission", where);
  if (s.kind == ShapeKind::curves) {
    // Fibres are opaque tubes: they bound no medium, emit nothing and are not glass (a ray
    // inside a thin round curve is not something Embree's curve intersector handles).
    if (!s.interior.empty() || !s.exterior.empty() || (s.emission != 0.0).any())
      fail("{}: curves cannot bound a medium or emit light", where);
    const MaterialKind k = s.material.empty() ? MaterialKind::diffuse : scene.materials.at(s.material).kind;
    if (s.material.empty() || (k != MaterialKind::diffuse && k != MaterialKind::mirror))
      fail("{}: curves need a diffuse or mirror material", where);
  }
  return s;
}

LightDesc parse_light(const json& j, const std::string& where, const std::filesystem::path& base_dir) {
  Reader r(j, where);
  LightDesc l;
  l.kind = parse_choice(where, "light type", r.string("type", ""), kLightKinds);
  switch (l.kind) {
    case LightKind::point:
      l.position = r.vec3("position", l.position);
      l.intensity = r.rgb("intensity", l.intensity);
      break;
    case LightKind::directional:
      l.direction = r.vec3("direction", l.direction);
      if (unit_vector(l.direction).isZero(0.0)) fail("{}: 'direction' must not be zero", where);
      l.direction = unit_vector(l.direction);
      l.intensity = r.rgb("irradiance", l.intensity);
      break;
    case LightKind::environment:
      if (r.has("image")) {
        // A lat-long radiance image times `scale`; `radiance` would be a second, conflicting scale.
        if (r.has("radiance")) fail("{}: give 'radiance' (constant) or 'image' (with 'scale'), not both", where);
        l.image = r.string("image", "");
        if (l.image.empty()) fail("{}: 'image' must name an EXR file", where);
        l.image = resolve_file(l.image, base_dir, where, "environment image");
        l.scale = r.non_negative("scale", l.scale);
      } else {
        l.intensity = r.rgb("radiance", l.intensity);
      }
      break;
  }
  r.finish();
  return l;
}

}  // namespace

SceneDesc parse_scene(std::string_view json_text, const std::string& source, const std::filesystem::path& base_dir) {
  // A file of another kind (a .vdb grid, an image) gets named, not a parser's "invalid JSON: ' B'".
  const std::string_view head = skip_utf8_bom(json_text).substr(0, 512);
  if (!looks_like_json(head)) {
    // JSON has no comments: a scene that starts with one is said as such, not as "a text file".
    const std::size_t first = head.find_first_not_of(" \t\r\n");
    if (first != std::string_view::npos && (head.substr(first, 2) == "//" || head.substr(first, 2) == "/*"))
      fail("{}: JSON has no comments: remove the comment at the start of the scene", source);
    fail("{}: not a scene JSON (looks like {})", source, file_kind(head));
  }
  const json root = parse_json_input(json_text, source);
  // weft gen's cloth.json is JSON too: say what it is and how to render it, not "unknown key 'crimp'".
  if (root.is_object() && !root.contains("camera") && !root.contains("shapes") &&
      (root.contains("warp_yarn") || root.contains("pattern")))
    fail(
        "{}: a weft gen cloth spec (cloth.json), not a scene: weft gen --config {} --out DIR writes DIR/scene.json "
        "for weft render",
        source, source);
  SceneDesc scene;
  scene.base_dir = base_dir;
  Reader r(root, source);
  if (r.has("camera")) scene.camera = parse_camera(r.at("camera"), source + ": camera");
  if (r.has("integrator")) scene.integrator = parse_integrator(r.at("integrator"), source + ": integrator");
  auto named_objects = [&](const std::string& key, auto&& parse_one, auto& table) {
    if (!r.has(key)) return;
    const json& j = r.at(key);
    if (!j.is_object()) fail("{}: '{}' must be an object of named entries", source, key);
    for (const auto& [name, value] : j.items())
      table[name] = parse_one(value, fmt::format("{}: {}.{}", source, key, name));
  };
  named_objects(
      "materials", [](const json& j, const std::string& w) { return parse_material(j, w); }, scene.materials);
  named_objects(
      "media", [&](const json& j, const std::string& w) { return parse_medium(j, w, base_dir); }, scene.media);
  auto lists = [&](const std::string& key, auto&& parse_one) {
    if (!r.has(key)) return;
    const json& j = r.at(key);
    if (!j.is_array()) fail("{}: '{}' must be an array", source, key);
    for (std::size_t i = 0; i < j.size(); ++i) parse_one(j[i], fmt::format("{}: {}[{}]", source, key, i));
  };
  lists("shapes", [&](const json& j, const std::string& w) { scene.shapes.push_back(parse_shape(j, w, scene)); });
  lists("lights", [&](const json& j, const std::string& w) { scene.lights.push_back(parse_light(j, w, base_dir)); });
  r.finish();
  // One image environment at most (the light sampler holds one map), and not mixed with constant ones.
  int env_images = 0;
  int env_constants = 0;
  for (const auto& l : scene.lights) {
    if (l.kind != LightKind::environment) continue;
    if (l.image.empty())
      ++env_constants;
    else
      ++env_images;
  }
  if (env_images > 1 || (env_images == 1 && env_constants > 0))
    fail("{}: an image environment must be the only environment light", source);
  // The laws of every medium are part of the description (no file is read to check them): a
  // misspelt law, a parameter out of range or a reciprocal partner that does not exist is an
  // error of the scene, reported here. Grids, fields and images are read by build_world.
  for (const auto& [name, m] : scene.media)
    if (m.kind != MediumKind::local_gamma) (void)make_medium_pair(m, fmt::format("{}: media.{}", source, name));
  scene.source = source;
  return scene;
}

SceneDesc load_scene(const std::filesystem::path& path) {
  // A folder opens and reads as nothing: it would be said to be "an empty file".
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail("scene file '{}': not a regular file (a folder)", path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("scene file '{}' cannot be opened (missing or unreadable)", path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path.string(), path.parent_path());
}

}  // namespace weft::render
