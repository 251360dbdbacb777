#include "weft/render/builtin_scenes.h"

#include "weft/core/error.h"
#include "weft/core/names.h"
#include "weft/render/scene.h"

namespace weft::render {

std::vector<std::string> builtin_scene_names() {
  std::vector<std::string> names;
  for (const auto& [name, text] : builtin_scene_table()) names.emplace_back(name);
  return names;
}

std::string_view builtin_scene(const std::string& name) {
  for (const auto& [n, text] : builtin_scene_table())
    if (n == name) return text;
  const auto names = builtin_scene_names();
  if (names.empty()) fail("no built-in scene '{}' (this build has none)", name);
  fail("no built-in scene '{}' (did you mean '{}'?)", name, closest_name(name, names));
}

}  // namespace weft::render
