// Transmission, single and multiple scattering of a study's images (render_components.h;
// docs/render.md §6e).
#include "weft/study/render_components.h"

#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/render/render.h"
#include "weft/study/bias_estimate.h"
#include "weft/study/render_study.h"

namespace weft::study {

using nlohmann::json;
using render::Image;

void check_component_scene(const render::SceneDesc& scene) {
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    const std::string& m = scene.shapes[i].material;
    if (m.empty()) continue;  // an emitter (or a black absorber): not a path event
    const auto it = scene.materials.find(m);
    if (it != scene.materials.end() && it->second.kind == render::MaterialKind::null) continue;
    fail(
        "study components: shapes[{}] has material '{}', which reflects; the single-scattering image (max_depth 1) "
        "counts the medium's events only in a scene whose surfaces are null boundaries and emitters",
        i, m);
  }
}

bool splits_components(const std::vector<std::string>& families, const std::string& name) {
  if (families.empty()) return false;
  if (name == "fine") return true;
  std::string family = name;
  const auto dash = name.rfind('-');
  if (dash != std::string::npos && name.ends_with("x") && name.size() > dash + 2 &&
      std::all_of(name.begin() + static_cast<std::ptrdiff_t>(dash) + 1, name.end() - 1,
                  [](char c) { return c >= '0' && c <= '9'; }))
    family = name.substr(0, dash);
  return std::any_of(families.begin(), families.end(),
                     [&](const std::string& f) { return f == "all" || f == family || f == name; });
}

ComponentRenders render_components(const json& scene, const std::string& medium, int spp, std::uint64_t seed,
                                   const std::filesystem::path& base_dir, ProgressSink& progress) {
  // Seeds 8 and 16 steps from the image's own: A, B, R and the background of a study use 0–3
  // steps, so the components of A (s), B (s + 1) and R (s + 2) are all independent of each other
  // and of every full image.
  render::RenderOptions ro;
  ro.spp = spp;
  ComponentRenders out;
  json transmission = scene;
  transmission["media"][medium]["albedo"] = json::array({0.0, 0.0, 0.0});
  ro.seed = seed + 8 * kStudySeedStep;
  out.transmission =
      render::render(render::parse_scene(transmission.dump(), "study component 'transmission'", base_dir), ro, progress)
          .image;
  json single = scene;
  single["integrator"]["max_depth"] = 1;
  ro.seed = seed + 16 * kStudySeedStep;
  out.upto_single =
      render::render(render::parse_scene(single.dump(), "study component 'single'", base_dir), ro, progress).image;
  return out;
}

Image difference_image(const Image& x, const Image& y) {
  if (x.width != y.width || x.height != y.height || x.rgb.size() != y.rgb.size())
    fail("study components: images differ in size ({}x{}, {}x{})", x.width, x.height, y.width, y.height);
  Image d = x;
  for (std::size_t i = 0; i < d.rgb.size(); ++i) d.rgb[i] = x.rgb[i] - y.rgb[i];
  d.variance.assign(d.rgb.size(), 0.0F);
  for (std::size_t i = 0; i < d.rgb.size(); ++i)
    d.variance[i] = (x.variance.empty() ? 0.0F : x.variance[i]) + (y.variance.empty() ? 0.0F : y.variance[i]);
  return d;
}

std::vector<ComponentBias> component_biases(const Image& a, const Image& b, const Image& r, const ComponentRenders& ca,
                                            const ComponentRenders& cb, const ComponentRenders& cr,
                                            const std::vector<bool>& mask) {
  std::vector<ComponentBias> out;
  const auto add = [&](const std::string& name, const Image& xa, const Image& xb, const Image& xr) {
    out.push_back({name, bias_by_scale(xa, xb, xr, mask, {1})});
  };
  add(kComponentNames[0], ca.transmission, cb.transmission, cr.transmission);
  add(kComponentNames[1], difference_image(ca.upto_single, ca.transmission),
      difference_image(cb.upto_single, cb.transmission), difference_image(cr.upto_single, cr.transmission));
  add(kComponentNames[2], difference_image(a, ca.upto_single), difference_image(b, cb.upto_single),
      difference_image(r, cr.upto_single));
  return out;
}

json component_biases_json(const std::vector<ComponentBias>& components) {
  json j = json::array();
  for (const ComponentBias& c : components) j.push_back({{"name", c.name}, {"bias", scale_bias_json(c.bias)}});
  return j;
}

std::vector<ComponentBias> component_biases_from_json(const json& j) {
  std::vector<ComponentBias> out;
  for (const auto& c : j) out.push_back({c.at("name").get<std::string>(), scale_bias_from_json(c.at("bias"))});
  return out;
}

std::string component_csv_header() {
  std::string h;
  for (const std::string& n : kComponentNames)
    h += fmt::format("{0}{1}_bias,{1}_bias_z,{1}_difference,{1}_difference_stderr", h.empty() ? "" : ",", n);
  return h;
}

std::string component_csv(const std::vector<ComponentBias>& components) {
  std::string row;
  for (std::size_t i = 0; i < kComponentNames.size(); ++i) {
    if (i > 0) row += ",";
    if (i >= components.size() || components[i].bias.blocks.empty()) {
      row += ",,,";
      continue;
    }
    const BlockBias& b = components[i].bias.blocks.front();
    const LevelBias& l = components[i].bias.level;
    row += fmt::format("{:.8g},{:.4g},{:.8g},{:.6g}", b.bias(), b.z(), l.difference, l.stderr_difference);
  }
  return row;
}

}  // namespace weft::study
