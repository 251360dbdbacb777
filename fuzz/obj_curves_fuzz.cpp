// libFuzzer target: OBJ polylines for cloth import (weft::curves::read_obj_curves).
#include "fuzz/harness.h"
#include "weft/curves/curve_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = weft::fuzz::scratch_file(data, size, ".obj");
  weft::fuzz::accept_or_reject([&] { (void)weft::curves::read_obj_curves(path); });
  return 0;
}
