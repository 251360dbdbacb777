#include "weft/core/paths.h"

namespace weft {

std::string resolve_beside(const std::string& name, const std::filesystem::path& base_dir) {
  std::filesystem::path p(name);
  if (p.is_relative()) p = base_dir / p;
  return std::filesystem::absolute(p).lexically_normal().string();
}

}  // namespace weft
