// libFuzzer target: the renderer's triangle-mesh OBJ reader (weft::render::load_obj).
#include "fuzz/harness.h"
#include "weft/render/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = weft::fuzz::scratch_file(data, size, ".obj");
  weft::fuzz::accept_or_reject([&] { (void)weft::render::load_obj(path); });
  return 0;
}
