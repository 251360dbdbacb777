// The cloth scene's light set-ups (cloth_scene.h, docs/render.md §5c): one table of names, each
// set-up holds the lights its name promises and nothing else, and a bad view is refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <filesystem>

#include "weft/core/error.h"
#include "weft/render/cloth_scene.h"
#include "weft/volume/provenance.h"

namespace weft::render {
namespace {

volume::Grid small_cloth() {
  volume::Grid g(0.02, "density");
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) g.set_value(i, j, (i + j) % 3, 0.3f);
  volume::Provenance prov;
  prov.units = "mm";
  prov.sigma = 100.0;
  volume::write_provenance(g, prov);
  return g;
}

struct Lights {
  int directional = 0;
  int environment = 0;
  int emitters = 0;
};

Lights lights_of(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text);
  Lights l;
  for (const auto& light : j.at("lights")) {
    if (light.at("type") == "directional") ++l.directional;
    if (light.at("type") == "environment") ++l.environment;
  }
  for (const auto& shape : j.at("shapes"))
    if (shape.contains("emission")) ++l.emitters;
  return l;
}

TEST(ClothScene, EveryLightingByNameHoldsItsLightsAndNoOthers) {
  const volume::Grid g = small_cloth();
  ASSERT_EQ(cloth_lightings().size(), 4U);
  for (const auto& [name, lighting] : cloth_lightings()) {
    EXPECT_EQ(cloth_lighting(name), lighting);
    EXPECT_EQ(cloth_lighting_name(lighting), name);
    ClothView view;
    view.lighting = lighting;
    const Lights l = lights_of(cloth_scene_json(g, "cloth.vdb", {}, view));
    const bool key = lighting != ClothLighting::back;
    const bool panel = lighting == ClothLighting::key_and_back || lighting == ClothLighting::back;
    EXPECT_EQ(l.directional, key ? 1 : 0) << name;
    EXPECT_EQ(l.emitters, panel ? 1 : 0) << name;
    // Only the default picture has a sky: the study's set-ups have a black background.
    EXPECT_EQ(l.environment, lighting == ClothLighting::key_and_back ? 1 : 0) << name;
  }
  EXPECT_THROW((void)cloth_lighting("sunset"), Error);
}

TEST(ClothScene, RefusesAFilmWithoutPixelsOrATiltPastTheHorizon) {
  const volume::Grid g = small_cloth();
  ClothView view;
  view.width = 0;
  EXPECT_THROW((void)cloth_scene_json(g, "cloth.vdb", {}, view), Error);
  view = {};
  view.tilt_degrees = 85.0;
  EXPECT_THROW((void)cloth_scene_json(g, "cloth.vdb", {}, view), Error);
}

/// The film's up direction as the camera uses it: `up` made orthogonal to the view, unit length.
std::array<double, 3> film_up(const nlohmann::json& camera) {
  std::array<double, 3> d{};
  std::array<double, 3> up{};
  for (std::size_t a = 0; a < 3; ++a) {
    d[a] = camera.at("look_at")[a].get<double>() - camera.at("position")[a].get<double>();
    up[a] = camera.at("up")[a].get<double>();
  }
  const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  const double ud = (up[0] * d[0] + up[1] * d[1] + up[2] * d[2]) / dd;
  std::array<double, 3> o{};
  for (std::size_t a = 0; a < 3; ++a) o[a] = up[a] - ud * d[a];
  const double n = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
  EXPECT_GT(n, 1e-9 * std::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2])) << "up along the view";
  for (double& x : o) x /= n;
  return o;
}

TEST(ClothScene, EveryTiltFromFaceOnToGrazingHasAnUpAcrossTheView) {
  // Face-on (tilt 0, `weft render --tilt 0`, `--study-tilts 0`) the normal is the view direction,
  // so it cannot be the film's up; the up used there must be the limit of the tilted views' up.
  const volume::Grid g = small_cloth();
  ClothView view;
  std::array<double, 3> face_on{};
  for (const double tilt : {0.0, 1e-300, 1e-16, 1e-4, 8.0, 45.0, 79.9}) {
    view.tilt_degrees = tilt;
    const nlohmann::json j = nlohmann::json::parse(cloth_scene_json(g, "cloth.vdb", {}, view));
    const std::array<double, 3> up = film_up(j.at("camera"));
    if (tilt == 0.0) face_on = up;
    if (tilt > 0.0 && tilt <= 1e-4) {
      for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(up[a], face_on[a], 1e-5) << tilt << " " << a;
    }
  }
  // And every one is a scene the renderer accepts (its camera checks: render/scene.h), down to
  // tilts so small that the normal's own projection orthogonal to the view underflows.
  const std::filesystem::path file = std::filesystem::path(testing::TempDir()) / "weft_cloth_face_on.vdb";
  g.save(file);
  for (const double tilt : {0.0, 1e-300, 1e-16, 1e-8}) {
    view.tilt_degrees = tilt;
    EXPECT_NO_THROW((void)cloth_scene(file, view)) << tilt;
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace weft::render
