// Laws ↔ JSON (law_json.h): the one place that knows the "inf" convention.
#include "weft/transmittance/law_json.h"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"

namespace weft::transmittance {

using json = nlohmann::json;

json parameter_to_json(double value, const std::string& where, const std::string& name) {
  if (value == std::numeric_limits<double>::infinity()) return "inf";
  if (!std::isfinite(value))
    fail("{}: law parameter '{}' is {}; a law in JSON holds numbers or \"inf\"", where, name, value);
  return value;
}

json law_to_json(const LawSpec& spec) {
  json j;
  j["name"] = spec.name;
  for (const auto& [k, v] : spec.params) j[k] = parameter_to_json(v, "law " + spec.name, k);
  if (!spec.table.empty()) j["table"] = spec.table;
  if (!spec.sampler.empty()) j["sampler"] = spec.sampler;
  return j;
}

LawSpec spec_of(const Law& law) {
  LawSpec spec;
  spec.name = law.name();
  for (const auto& p : law.parameters()) spec.params[p.name] = p.value;
  spec.sampler = law.sampler_choice();
  return spec;
}

LawSpec law_from_json(const json& j, const std::string& where) {
  LawSpec spec;
  if (j.is_string()) {
    spec.name = j.get<std::string>();
    return spec;
  }
  if (!j.is_object()) fail("{}: a law is a name or an object {{\"name\": ..., parameters}}, got {}", where, j.dump());
  for (const auto& [key, value] : j.items()) {
    if (key == "name") {
      if (!value.is_string()) fail("{}: 'name' must be a string", where);
      spec.name = value.get<std::string>();
    } else if (key == "table") {
      if (!value.is_string()) fail("{}: 'table' must be a file name", where);
      spec.table = value.get<std::string>();
    } else if (key == "sampler") {
      if (!value.is_string()) fail("{}: 'sampler' must be a string", where);
      spec.sampler = value.get<std::string>();
    } else if (value.is_string() && value.get<std::string>() == "inf") {
      // α = ∞ (the exponential limit); the law decides whether it accepts it.
      spec.params[key] = std::numeric_limits<double>::infinity();
    } else {
      if (!value.is_number())
        fail("{}: law parameter '{}' must be a number (or \"inf\"), got {}", where, key, value.dump());
      const double x = value.get<double>();
      if (!std::isfinite(x)) fail("{}: law parameter '{}' must be finite", where, key);
      spec.params[key] = x;
    }
  }
  if (spec.name.empty()) fail("{}: missing required key 'name'", where);
  return spec;
}

}  // namespace weft::transmittance
