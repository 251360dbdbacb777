#include "written_files.h"

#include <iterator>
#include <stdexcept>

#include <fmt/format.h>

namespace weft::app {

namespace fs = std::filesystem;

std::string human_size(std::uintmax_t bytes) {
  if (bytes < 1024) return fmt::format("{} B", bytes);
  constexpr const char* kUnits[] = {"KiB", "MiB", "GiB", "TiB"};
  double v = static_cast<double>(bytes) / 1024.0;
  std::size_t u = 0;
  while (v >= 1024.0 && u + 1 < std::size(kUnits)) {
    v /= 1024.0;
    ++u;
  }
  return fmt::format("{:.1f} {}", v, kUnits[u]);
}

void WrittenFiles::add(const fs::path& path, const std::string& what) {
  std::error_code ec;
  const std::uintmax_t bytes = fs::file_size(path, ec);
  // A file the command just wrote and cannot stat is the app's bug, not the user's input.
  if (ec) throw std::runtime_error(fmt::format("{}: written but cannot stat: {}", path.string(), ec.message()));
  for (auto& e : entries_) {
    if (e.path == path) {
      e.bytes = bytes;
      if (!what.empty()) e.what = what;
      return;
    }
  }
  entries_.push_back({path, bytes, what});
}

std::uintmax_t WrittenFiles::total_bytes() const {
  std::uintmax_t total = 0;
  for (const auto& e : entries_) total += e.bytes;
  return total;
}

nlohmann::json WrittenFiles::to_json(const fs::path& folder) const {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : entries_) {
    fs::path name = e.path;
    if (!folder.empty()) {
      const fs::path rel = e.path.lexically_relative(folder);
      if (!rel.empty() && *rel.begin() != "..") name = rel;
    }
    nlohmann::json j = {{"file", name.generic_string()}, {"bytes", e.bytes}};
    if (!e.what.empty()) j["what"] = e.what;
    out.push_back(j);
  }
  return out;
}

void WrittenFiles::say(const Context& ctx) const {
  for (const auto& e : entries_) {
    ctx.say(fmt::format("wrote {} ({}{}{})", e.path.string(), human_size(e.bytes), e.what.empty() ? "" : ", ", e.what));
  }
}

}  // namespace weft::app
