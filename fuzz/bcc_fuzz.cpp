// libFuzzer target: the BCC curve reader (weft::curves::parse_bcc).
#include "fuzz/harness.h"
#include "weft/curves/curve_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Few Catmull-Rom subdivisions keep large valid inputs cheap; the parser's checks do not depend on it.
  weft::fuzz::accept_or_reject([&] { (void)weft::curves::parse_bcc(weft::fuzz::as_text(data, size), "<fuzz>", 2); });
  return 0;
}
