// The cloth scene's light set-ups (cloth_scene.h, docs/render.md §5c): one table of names, each
// set-up holds the lights its name promises and nothing else, and a bad view is refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

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

}  // namespace
}  // namespace weft::render
