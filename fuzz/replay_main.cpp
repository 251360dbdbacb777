// Replays inputs through one fuzz target's LLVMFuzzerTestOneInput without libFuzzer (docs/robustness.md),
// so the ordinary build (gcc, no fuzzer runtime) guards every crash input kept in
// tests/data/fuzz_regressions/<target>/: fuzz/targets.cmake links this main with each
// fuzz/<target>_fuzz.cpp as `fuzz_replay_<target>` and registers one CTest per input.
//
// Usage: fuzz_replay_TARGET FILE|FOLDER...  (a folder stands for the regular files in it)
// Exit 0 when every input is accepted or rejected with weft::Error; a crash, a sanitizer report
// or an escaping exception of another type fails (non-zero exit, the input named on stderr).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <typeinfo>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::filesystem::path> inputs_of(int argc, char** argv) {
  std::vector<std::filesystem::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path arg(argv[i]);
    if (std::filesystem::is_directory(arg)) {
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(arg))
        if (entry.is_regular_file()) files.push_back(entry.path());
      std::sort(files.begin(), files.end());
      inputs.insert(inputs.end(), files.begin(), files.end());
    } else {
      inputs.push_back(arg);
    }
  }
  return inputs;
}

}  // namespace

int main(int argc, char** argv) {
  const auto inputs = inputs_of(argc, argv);
  if (inputs.empty()) {
    std::cerr << "usage: " << (argc > 0 ? argv[0] : "fuzz_replay") << " FILE|FOLDER...\n";
    return 2;
  }
  for (const auto& path : inputs) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      std::cerr << path.string() << ": cannot open\n";
      return 2;
    }
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::cerr << "replaying " << path.string() << " (" << bytes.size() << " bytes)\n";
    try {
      (void)LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    } catch (const std::exception& e) {
      std::cerr << path.string() << ": escaped exception " << typeid(e).name() << ": " << e.what() << "\n";
      return 1;
    } catch (...) {
      std::cerr << path.string() << ": escaped exception of unknown type\n";
      return 1;
    }
  }
  std::cerr << "replayed " << inputs.size() << " input(s): no crash\n";
  return 0;
}
