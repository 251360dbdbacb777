// libFuzzer target: the JSON scene parser (weft::render::parse_scene) and the media it describes
// (weft::render::build_medium, what build_world does for each medium before any geometry).
#include "fuzz/harness.h"
#include "weft/render/scene.h"
#include "weft/render/world.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Relative mesh paths resolve into a folder that does not exist, so only absolute paths in the
  // input can name real files.
  weft::fuzz::accept_or_reject([&] {
    const weft::render::SceneDesc scene =
        weft::render::parse_scene(weft::fuzz::as_text(data, size), "<fuzz>", "/nonexistent/weft-fuzz");
    for (const auto& [name, medium] : scene.media) (void)weft::render::build_medium(scene, name);
  });
  return 0;
}
