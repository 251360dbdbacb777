#pragma once
/// @file
/// @brief One function per fuzz target: feed untrusted bytes to one of weft's loaders.
///
/// Each function returns normally when the loader accepts the bytes or rejects them with
/// weft::Error (the promised behaviour for bad input); anything else (a crash, a sanitizer
/// report, another exception type, an allocation beyond the fuzzer's limit, a hang) is a bug.
/// The libFuzzer entry points (fuzz/*_fuzz.cpp) and the regression replay both call these.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <unistd.h>

#include "weft/core/error.h"

namespace weft::fuzz {

/// The bytes as text.
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Writes the bytes to a per-process scratch file with extension `ext` (for loaders that take a
/// path) and returns its path; the file is overwritten by the next input.
inline std::filesystem::path scratch_file(const std::uint8_t* data, std::size_t size, const std::string& ext) {
  const auto path =
      std::filesystem::temp_directory_path() / ("weft-fuzz-" + std::to_string(static_cast<long>(::getpid())) + ext);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw std::runtime_error("fuzz harness: cannot write " + path.string());
  return path;
}

/// Runs `load`, treating weft::Error as a clean rejection.
template <typename F>
void accept_or_reject(F&& load) {
  try {
    load();
  } catch (const weft::Error&) {
  }
}

}  // namespace weft::fuzz
