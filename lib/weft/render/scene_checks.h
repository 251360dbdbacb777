#pragma once
/// @file
/// @brief What a scene says that cannot reach the image, as warnings: the CLI prints them as
/// `weft: warning: ...` on stderr and the Python module raises them as `weft.Warning`, a
/// UserWarning (docs/scene-format.md "Warnings"). One list, for both front ends.

#include <string>
#include <vector>

#include "weft/render/scene.h"
#include "weft/render/world.h"

namespace weft::render {

/// @brief One line per medium that no shape names as its interior or exterior: it is parsed (and
/// its files read) but nothing renders through it, often a misspelt or forgotten reference.
[[nodiscard]] std::vector<std::string> scene_warnings(const SceneDesc& scene);

/// @brief One line per medium of the built world whose extinction is 0 everywhere (a grid whose
/// active voxels are all 0, or a zero σ or μ; MediumTraits::empty): light passes it untouched,
/// often a grid written from the wrong array or an extinction grid read as concentration.
/// (A grid with no active voxel at all is already an error of build_world.)
[[nodiscard]] std::vector<std::string> world_warnings(const World& world);

}  // namespace weft::render
