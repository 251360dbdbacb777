#pragma once
/// @file
/// @brief The example scenes of the repository's scenes/ folder, compiled into the library.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace weft::render {

/// (name, JSON text) of every built-in scene, sorted by name.
const std::vector<std::pair<std::string_view, std::string_view>>& builtin_scene_table();

/// Names of the built-in scenes.
[[nodiscard]] std::vector<std::string> builtin_scene_names();

/// The JSON text of built-in scene `name`; throws weft::Error (suggesting the closest name)
/// when there is none.
[[nodiscard]] std::string_view builtin_scene(const std::string& name);

/// Label of the scene `weft render` renders when given none: the default cloth of `weft gen`
/// as a grid medium (cloth_scene.h), not a built-in JSON scene.
inline constexpr const char* kDefaultScene = "default_cloth";

}  // namespace weft::render
