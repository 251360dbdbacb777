#pragma once
// Scenes and images as the render bindings take and give them (render.cpp, study.cpp).

#include <string>
#include <vector>

#include "common.h"
#include "weft/render/image.h"
#include "weft/render/scene.h"

namespace weft::python {

/// The scene of a binding's (kind, text, base_dir): kind "file" (a path), "builtin" (a built-in
/// scene's name) or "dict" (JSON text; relative names against base_dir, else the current folder).
render::SceneDesc scene_of(const std::string& kind, const std::string& text, const std::string& base_dir);

/// An image's values (its rgb or its variance) as a float32 array (H, W, 3).
py::array_t<float> image_array(const render::Image& image, const std::vector<float>& values);

}  // namespace weft::python
