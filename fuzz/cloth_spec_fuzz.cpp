// libFuzzer target: the cloth generator's JSON config (weft::cloth::cloth_spec_from_json), then
// the checks `weft gen` runs on it before generating.
#include "data_gen/cloth/spec.h"
#include "fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  weft::fuzz::accept_or_reject([&] {
    const auto spec = weft::cloth::cloth_spec_from_json(std::string(weft::fuzz::as_text(data, size)), "<fuzz>");
    weft::cloth::validate(spec);
    weft::cloth::validate(weft::cloth::resolve(spec));
  });
  return 0;
}
