// libFuzzer target: .vdb files through weft's grid loader (weft::volume::Grid::load), which
// takes a path: the bytes go to a scratch file first.
#include "fuzz/harness.h"
#include "weft/volume/grid.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = weft::fuzz::scratch_file(data, size, ".vdb");
  weft::fuzz::accept_or_reject([&] { (void)weft::volume::Grid::load(path); });
  return 0;
}
