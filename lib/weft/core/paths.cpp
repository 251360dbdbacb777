#include "weft/core/paths.h"

#include <algorithm>
#include <cctype>

namespace weft {

std::string resolve_beside(const std::string& name, const std::filesystem::path& base_dir) {
  std::filesystem::path p(name);
  if (p.is_relative()) p = base_dir / p;
  return std::filesystem::absolute(p).lexically_normal().string();
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext;
}

}  // namespace weft
