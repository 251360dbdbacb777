// Finished units on disk (unit_store.h).
#include "weft/dist/unit_store.h"

#include <fstream>
#include <iterator>
#include <system_error>

#include <fmt/core.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"

namespace weft::dist {
namespace fs = std::filesystem;

namespace {
std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) fail("cannot read '{}'", p.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
}  // namespace

UnitStore::UnitStore(fs::path folder, std::string key, bool resume, FrontEnd front)
    : folder_(std::move(folder)), key_(std::move(key)), resume_(resume), front_(front) {}

fs::path UnitStore::unit_path(std::size_t unit) const { return folder_ / fmt::format("unit-{:06}.bin", unit); }

void UnitStore::open() {
  std::error_code ec;
  const fs::path key_file = folder_ / "run.json";
  if (resume_ && fs::exists(key_file, ec)) {
    if (read_file(key_file) != key_) {
      const std::string option = Spelling{"--resume", "resume=True"}.in(front_);
      fail(
          "{}: '{}' holds the units of a different run (its run.json differs from this run's options); "
          "rerun with the same options, or without {} to start over",
          option, folder_.string(), option);
    }
    return;
  }
  // A fresh start: units of an earlier run in this folder must not leak into this one.
  if (fs::exists(folder_, ec)) {
    for (const auto& entry : fs::directory_iterator(folder_, ec)) {
      const std::string n = entry.path().filename().string();
      if (n.starts_with("unit-") || n == "run.json") fs::remove(entry.path(), ec);
    }
  }
  ensure_directory(folder_);
  write_text_atomically(key_file, key_);
}

std::optional<Bytes> UnitStore::load(std::size_t unit) const {
  const fs::path p = unit_path(unit);
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) return std::nullopt;
  const std::string s = read_file(p);
  return Bytes(s.begin(), s.end());
}

void UnitStore::save(std::size_t unit, const Bytes& bytes) const {
  write_text_atomically(unit_path(unit), std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

void UnitStore::remove() const {
  if (!is_root()) return;
  std::error_code ec;
  fs::remove_all(folder_, ec);
}

}  // namespace weft::dist
