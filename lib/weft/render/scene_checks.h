#pragma once
/// @file
/// @brief What a scene says that cannot reach the image, as warnings the CLI prints and the
/// Python module raises as UserWarning (docs/python.md "One set of checks").

#include <string>
#include <vector>

#include "weft/render/scene.h"

namespace weft::render {

/// @brief One line per medium that no shape names as its interior or exterior: it is parsed (and
/// its files read) but nothing renders through it, often a misspelt or forgotten reference.
[[nodiscard]] std::vector<std::string> scene_warnings(const SceneDesc& scene);

}  // namespace weft::render
