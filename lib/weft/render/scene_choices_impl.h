#pragma once
/// @file
/// @brief The names of a scene description's choices (internal; not installed): material,
/// medium, tracking, shape and light kinds, pair modes, origins and memory rules, each with its
/// one spelling in scene files (docs/scene-format.md), shared by the reader (scene.cpp) and the
/// writer (scene_json.cpp).

#include <string>
#include <utility>
#include <vector>

#include "weft/render/scene.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/transmittance/pair.h"

namespace weft::render {

template <typename Enum>
std::string choice_name(Enum e, const std::vector<std::pair<std::string, Enum>>& choices) {
  for (const auto& [name, c] : choices)
    if (c == e) return name;
  return "?";
}

inline const std::vector<std::pair<std::string, MaterialKind>> kMaterialKinds = {
    {"diffuse", MaterialKind::diffuse},
    {"mirror", MaterialKind::mirror},
    {"dielectric", MaterialKind::dielectric},
    {"null", MaterialKind::null}};
/// The memory rules by their names (transmittance::memory_rule_name, the one spelling).
inline const std::vector<std::pair<std::string, transmittance::MemoryRule>>& memory_rules() {
  static const auto rules = [] {
    std::vector<std::pair<std::string, transmittance::MemoryRule>> v;
    for (const auto r : transmittance::kMemoryRules) v.emplace_back(transmittance::memory_rule_name(r), r);
    return v;
  }();
  return rules;
}
inline const std::vector<std::pair<std::string, MediumKind>> kMediumKinds = {
    {"homogeneous", MediumKind::homogeneous}, {"grid", MediumKind::grid}, {"local-gamma", MediumKind::local_gamma}};
inline const std::vector<std::pair<std::string, Tracking>> kTrackings = {{"delta", Tracking::delta},
                                                                         {"optical-depth", Tracking::optical_depth}};
inline const std::vector<std::pair<std::string, ShapeKind>> kShapeKinds = {{"sphere", ShapeKind::sphere},
                                                                           {"box", ShapeKind::box},
                                                                           {"rectangle", ShapeKind::rectangle},
                                                                           {"mesh", ShapeKind::mesh},
                                                                           {"curves", ShapeKind::curves}};
inline const std::vector<std::pair<std::string, LightKind>> kLightKinds = {
    {"point", LightKind::point}, {"directional", LightKind::directional}, {"environment", LightKind::environment}};
inline const std::vector<std::pair<std::string, transmittance::PairMode>> kModes = {
    {"reciprocal", transmittance::PairMode::reciprocal},
    {"same", transmittance::PairMode::same},
    {"explicit", transmittance::PairMode::explicit_}};
inline const std::vector<std::pair<std::string, transmittance::Origin>> kOrigins = {
    {"source", transmittance::Origin::source}, {"scatterer", transmittance::Origin::scatterer}};

}  // namespace weft::render
