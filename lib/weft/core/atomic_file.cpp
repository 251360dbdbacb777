#include "weft/core/atomic_file.h"

#include <atomic>
#include <fstream>
#include <system_error>

#include <unistd.h>

#include "weft/core/error.h"

namespace weft {
namespace fs = std::filesystem;

namespace {
fs::path temporary_beside(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  fs::path tmp = target;
  // Keep the extension last: some writers (VTK, OpenEXR) choose a format from it.
  tmp.replace_filename(
      fmt::format(".{}.tmp{}-{}{}", target.stem().string(), ::getpid(), counter++, target.extension().string()));
  return tmp;
}
}  // namespace

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) fail("output folder '{}' does not exist", dir.string());
  if (::access(dir.c_str(), W_OK) != 0) fail("output folder '{}' is not writable", dir.string());
  const fs::path tmp = temporary_beside(target);
  try {
    write(tmp);
    if (!fs::exists(tmp, ec)) fail("writing '{}' produced no file", target.string());
    fs::rename(tmp, target, ec);
    if (ec) fail("cannot rename '{}' to '{}': {}", tmp.string(), target.string(), ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void write_text_atomically(const fs::path& target, std::string_view text) {
  write_atomically(target, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) fail("cannot open '{}' for writing", target.string());
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.flush();
    if (!out) fail("cannot write '{}' (disk full?)", target.string());
  });
}

void ensure_directory(const fs::path& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  fs::create_directories(dir, ec);
  if (ec) fail("cannot create output folder '{}': {}", dir.string(), ec.message());
}

OutputFolder::OutputFolder(const fs::path& dir) {
  std::error_code ec;
  for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    created_.push_back(p);
    if (p == p.parent_path()) break;
  }
  try {
    ensure_directory(dir);
  } catch (...) {
    remove_empty();  // create_directories may have stopped half way
    throw;
  }
}

OutputFolder::~OutputFolder() { remove_empty(); }

void OutputFolder::remove_empty() noexcept {
  std::error_code ec;
  for (const fs::path& p : created_) {
    // Only an empty folder goes: one holding a file (or not made by us after all) stays.
    if (!fs::is_directory(p, ec) || !fs::is_empty(p, ec) || ec) break;
    fs::remove(p, ec);
    if (ec) break;
  }
  created_.clear();
}

}  // namespace weft
