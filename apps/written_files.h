#pragma once
/// @file
/// @brief What a command wrote: every file with its size, said the same way by every command
/// ("wrote out/cloth.vdb (1.2 MiB, grid)") and listed in its JSON report.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.h"

namespace weft::app {

/// @brief "512 B", "1.2 KiB", "3.4 MiB", "1.0 GiB" (binary prefixes, one decimal).
std::string human_size(std::uintmax_t bytes);

/// @brief The files a run wrote, in the order written.
class WrittenFiles {
 public:
  struct Entry {
    std::filesystem::path path;
    std::uintmax_t bytes = 0;
    std::string what;  ///< e.g. "grid", "ground-truth curves"; may be empty
  };

  /// Records `path` (which must exist: call it after the write) with its size now.
  /// Recording a path again updates its size (a report rewritten after the plots).
  void add(const std::filesystem::path& path, const std::string& what = "");

  [[nodiscard]] const std::vector<Entry>& entries() const { return entries_; }
  [[nodiscard]] std::uintmax_t total_bytes() const;

  /// `[{"file": "cloth.vdb", "bytes": 123, "what": "grid"}, …]`, file names relative to `folder`
  /// when inside it (a report lists its siblings, not the absolute paths of the run).
  [[nodiscard]] nlohmann::json to_json(const std::filesystem::path& folder = {}) const;

  /// One line per file through ctx.say: "wrote <path> (<size>[, <what>])".
  void say(const Context& ctx) const;

 private:
  std::vector<Entry> entries_;
};

}  // namespace weft::app
