#include "data_gen/media2d/realization_structure.h"

#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>

#include "data_gen/media2d/medium.h"
#include "data_gen/media2d/realization_tallies.h"

namespace weft::media2d {

using nlohmann::json;

namespace {

json structure_json(const StructureStats& s) {
  return {{"realization", s.realization},
          {"points", s.points},
          {"delaunay_ok", s.delaunay_ok},
          {"note", s.note},
          {"mean_nn", s.mean_nn},
          {"sd_nn", s.sd_nn},
          {"mean_delaunay_degree", s.mean_delaunay_degree},
          {"nn_edges", s.nn_edges},
          {"nn_density", s.nn_density},
          {"g_centres", s.g_centres},
          {"g", s.g},
          {"max_overlap_fraction", s.max_overlap_fraction}};
}

StructureStats structure_from(const json& j) {
  StructureStats s;
  s.realization = j.at("realization").get<std::size_t>();
  s.points = j.at("points").get<std::size_t>();
  s.delaunay_ok = j.at("delaunay_ok").get<bool>();
  s.note = j.at("note").get<std::string>();
  s.mean_nn = j.at("mean_nn").get<double>();
  s.sd_nn = j.at("sd_nn").get<double>();
  s.mean_delaunay_degree = j.at("mean_delaunay_degree").get<double>();
  j.at("nn_edges").get_to(s.nn_edges);
  j.at("nn_density").get_to(s.nn_density);
  j.at("g_centres").get_to(s.g_centres);
  j.at("g").get_to(s.g);
  s.max_overlap_fraction = j.at("max_overlap_fraction").get<double>();
  return s;
}

}  // namespace

StructureStats realization_structure(const SimulationSpec& spec, std::size_t e, std::size_t j) {
  const Medium medium = realization(spec, e, j);
  if (medium.centers.size() <= spec.structure_max_points) return structure_stats(medium, j);
  // Stand-in with n' = structure_max_points particles: λ' solves n' = 1/(2rλ' + πr²).
  MediumSpec small{spec.etas[e], spec.radius, spec.mean_free_path, spec.cluster_size, spec.step_unit};
  const double n_small = static_cast<double>(spec.structure_max_points);
  small.mean_free_path = (1.0 / n_small - std::numbers::pi * spec.radius * spec.radius) / (2.0 * spec.radius);
  if (spec.step_unit > 0.0)
    small.step_unit = spec.step_unit * std::sqrt(static_cast<double>(medium.centers.size()) / n_small);
  Pcg32 stand_in_rng = stream_for(spec.seed, unit_key(e, j) | 3U);
  StructureStats s = structure_stats(generate(small, stand_in_rng), j);
  s.note = fmt::format(
      "measured on a stand-in realization of the same generator with {} particles (the medium has {}); "
      "distances in units of the mean spacing",
      s.points, medium.centers.size());
  return s;
}

dist::Bytes encode(const StructureStats& s) { return json::to_msgpack(structure_json(s)); }

StructureStats decode_structure(const dist::Bytes& b) { return structure_from(json::from_msgpack(b)); }

}  // namespace weft::media2d
