// libFuzzer target: the JSON scene parser (weft::render::parse_scene).
#include "fuzz/harness.h"
#include "weft/render/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Relative mesh paths resolve into a folder that does not exist, so only absolute paths in the
  // input can name real files.
  weft::fuzz::accept_or_reject(
      [&] { (void)weft::render::parse_scene(weft::fuzz::as_text(data, size), "<fuzz>", "/nonexistent/weft-fuzz"); });
  return 0;
}
