#include "weft/volume/provenance.h"

#include <cmath>
#include <numbers>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/core/parse_number.h"

namespace weft::volume {
namespace {

double positive_number(const std::string& key, const std::string& text) {
  const double v = parse_number(text).value_or(NAN);
  if (!std::isfinite(v) || !(v > 0.0)) fail("grid metadata '{}' = '{}' is not a positive number", key, text);
  return v;
}

/// Envelope radius of a yarn preset as the generator computes it (data_gen/cloth/spec.cpp,
/// yarn_envelope_radius): plies at their largest migration radius.
double envelope_radius(const nlohmann::json& y) {
  const double ply_offset = y.at("ply_offset").get<double>();
  const double ply_radius = y.at("ply_radius").get<double>();
  const double en = y.at("ellipse_n").get<double>();
  const double eb = y.at("ellipse_b").get<double>();
  const double rho_max = y.at("rho_max").get<double>();
  return ply_offset + ply_radius * std::max(en, eb) * rho_max;
}

}  // namespace

SigmaChoice resolve_sigma(const Provenance& p, std::optional<double> given, bool extinction, const std::string& what,
                          FrontEnd asker) {
  const bool cli = asker == FrontEnd::cli;
  if (extinction) return {1.0, "values are extinction (mu), sigma = 1"};
  if (given) return {*given, cli ? "--sigma" : "sigma="};
  if (p.sigma) return {*p.sigma, fmt::format("{} provenance: {}", cli ? what : "grid", p.sigma_rule)};
  fail("{}: concentration grid without sigma in its metadata (not written by weft gen); pass {}", what,
       cli ? "--sigma S (extinction per unit concentration, 1/length) or --values extinction" : "sigma=S");
}

void require_value_kind(const Provenance& p, bool read_as_extinction, const std::string& what, ValuesAsker asker) {
  if (p.value_kind != "concentration" && p.value_kind != "extinction") return;
  if ((p.value_kind == "extinction") == read_as_extinction) return;
  fail("{}: the grid's metadata says its values are {}; {}", what, p.value_kind,
       asker == ValuesAsker::cli ? fmt::format("pass --values {}", p.value_kind)
                                 : fmt::format("set \"values\": \"{}\"", p.value_kind));
}

double fibre_sigma(double fiber_radius) {
  require_positive("fibre radius", fiber_radius);
  return 2.0 / (std::numbers::pi * fiber_radius);
}

Provenance read_provenance(const Grid& grid) {
  const auto meta = grid.metadata();
  auto get = [&](const std::string& key) -> std::optional<std::string> {
    const auto it = meta.find(key);
    if (it == meta.end()) return std::nullopt;
    return it->second;
  };
  Provenance p;
  if (auto u = get("weft:units"))
    p.units = *u;
  else if (auto u2 = get("units"))
    p.units = *u2;
  if (auto k = get("weft:value_kind"))
    p.value_kind = *k;
  else if (auto k2 = get("value_kind"))
    p.value_kind = *k2;
  if (auto s = get("weft:sigma_per_concentration")) {
    p.sigma = positive_number("weft:sigma_per_concentration", *s);
    p.sigma_rule = get("weft:sigma_rule").value_or("recorded by the generator");
    p.source = "weft gen";
  }
  if (auto r = get("weft:fiber_radius")) p.fiber_radius = positive_number("weft:fiber_radius", *r);
  if (auto d = get("weft:yarn_diameter")) p.yarn_diameter = positive_number("weft:yarn_diameter", *d);
  if (p.sigma && p.yarn_diameter) return p;
  // Grids of earlier weft versions: the generator's parameters as JSON.
  const auto gen = get("generator");
  if (!gen) return p;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(*gen);
    const auto& warp = j.at("warp_yarn");
    const auto& weft = j.at("weft_yarn");
    const double rw = warp.at("fiber_radius").get<double>();
    const double rf = weft.at("fiber_radius").get<double>();
    if (!(rw > 0.0) || !(rf > 0.0)) fail("fibre radius not positive");
    if (!p.fiber_radius) p.fiber_radius = 0.5 * (rw + rf);
    if (!p.sigma) {
      // Without per-preset fibre volumes, the two presets count equally.
      p.sigma = 0.5 * (fibre_sigma(rw) + fibre_sigma(rf));
      p.sigma_rule = "2/(pi r_f) from the generator's fibre radius (opaque fibres across the beam)";
      p.source = "weft gen (legacy metadata)";
    }
    if (!p.yarn_diameter) p.yarn_diameter = envelope_radius(warp) + envelope_radius(weft);
  } catch (const nlohmann::json::exception& e) {
    fail("grid metadata 'generator' is not weft's cloth JSON: {}", e.what());
  } catch (const Error& e) {
    fail("grid metadata 'generator': {}", e.what());
  }
  if (p.units.empty()) p.units = "mm";
  return p;
}

void write_provenance(Grid& grid, const Provenance& p) {
  if (!p.units.empty()) grid.set_metadata("weft:units", p.units);
  if (!p.value_kind.empty()) grid.set_metadata("weft:value_kind", p.value_kind);
  if (p.sigma) grid.set_metadata("weft:sigma_per_concentration", fmt::format("{:.17g}", *p.sigma));
  if (!p.sigma_rule.empty()) grid.set_metadata("weft:sigma_rule", p.sigma_rule);
  if (p.fiber_radius) grid.set_metadata("weft:fiber_radius", fmt::format("{:.17g}", *p.fiber_radius));
  if (p.yarn_diameter) grid.set_metadata("weft:yarn_diameter", fmt::format("{:.17g}", *p.yarn_diameter));
}

}  // namespace weft::volume
