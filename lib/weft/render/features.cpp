#include "weft/render/features.h"

namespace weft::render {

std::vector<std::string> Features::names() const {
  std::vector<std::string> out{"surfaces"};
  if (area_lights) out.emplace_back("area lights");
  if (environment) out.emplace_back(environment_image ? "image environment" : "environment");
  if (curves) out.emplace_back("curves");
  // Each medium as it is rendered: kind, law and estimator (asked from the medium).
  for (const auto& m : media_described) out.push_back(m);
  return out;
}

}  // namespace weft::render
