#include "data_gen/media2d/realization_tallies.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"

namespace weft::media2d {

using nlohmann::json;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

json tally_json(const Tally& t) {
  return {{"c", t.counts}, {"o", t.offsets}, {"s", t.survivors}, {"t", t.truncated_sum}, {"n", t.n}};
}

Tally tally_from(const json& j) {
  Tally t(0);
  j.at("c").get_to(t.counts);
  j.at("o").get_to(t.offsets);
  t.survivors = j.at("s").get<std::uint32_t>();
  t.truncated_sum = j.at("t").get<double>();
  t.n = j.at("n").get<std::uint32_t>();
  return t;
}

}  // namespace

dist::Bytes encode(const RealizationOut& r) {
  json j;
  j["theta"] = json::array();
  for (const auto& t : r.theta) j["theta"].push_back(tally_json(t));
  j["iso"] = tally_json(*r.iso);
  j["scatterer"] = tally_json(*r.scatterer);
  j["boundary"] = json::array();
  for (const auto& t : r.boundary) j["boundary"].push_back(tally_json(t));
  j["perturbed"] = r.perturbed;
  j["count"] = r.count;
  return json::to_msgpack(j);
}

RealizationOut decode(const dist::Bytes& b) {
  const json j = json::from_msgpack(b);
  RealizationOut r;
  for (const auto& t : j.at("theta")) r.theta.push_back(tally_from(t));
  r.iso = tally_from(j.at("iso"));
  r.scatterer = tally_from(j.at("scatterer"));
  for (const auto& t : j.at("boundary")) r.boundary.push_back(tally_from(t));
  r.perturbed = j.at("perturbed").get<std::size_t>();
  r.count = j.at("count").get<std::size_t>();
  return r;
}

std::uint64_t unit_key(std::size_t eta_index, std::size_t realization) {
  return (static_cast<std::uint64_t>(eta_index) << 40U) | (static_cast<std::uint64_t>(realization) << 4U);
}

Point2 source_origin(const DiskGrid& grid, Pcg32& rng, bool on_boundary_line) {
  for (int attempt = 0; attempt < 10000; ++attempt) {
    const double x = on_boundary_line ? 0.0 : rng.uniform();
    const Point2 o{x, rng.uniform()};
    // Sources sit in the void between particles.
    if (!grid.inside_any(o)) return o;
  }
  fail("sim2d: could not place a source outside the disks (packing too dense)");
}

Point2 direction_deg(double theta_deg) {
  // Reduced to [0°, 360°) first: fmod is exact, so any finite θ (1e308 included, whose θ·π
  // overflowed to inf) gives its direction, and the axes come out exact: θ = 90° is (0, 1), not
  // (6e-17, 1), so such a ray repeats after one domain length (disk_grid.h) instead of drifting.
  double reduced = std::fmod(theta_deg, 360.0);
  if (reduced < 0.0) reduced += 360.0;  // may round to 360 for a tiny negative θ
  if (reduced == 0.0 || reduced == 360.0) return {1.0, 0.0};
  if (reduced == 90.0) return {0.0, 1.0};
  if (reduced == 180.0) return {-1.0, 0.0};
  if (reduced == 270.0) return {0.0, -1.0};
  const double a = reduced * std::numbers::pi / 180.0;
  return {std::cos(a), std::sin(a)};
}

RealizationOut trace_realization(const SimulationSpec& spec, std::size_t e, std::size_t j) {
  const std::size_t bins = spec.bins;
  const double width = spec.t_max / static_cast<double>(bins);
  const double lambda = spec.mean_free_path;
  const double reach = spec.t_max * lambda;
  const std::uint64_t base = unit_key(e, j);
  Pcg32 rays = stream_for(spec.seed, base | 1U);
  Pcg32 shift_rng = stream_for(spec.seed, base | 2U);
  const Medium medium = realization(spec, e, j);
  const DiskGrid grid(medium);
  RealizationOut out;
  out.perturbed = medium.perturbed;
  out.count = medium.centers.size();
  for (const double theta : spec.thetas_deg) {
    Tally tally(bins);
    const Point2 d = direction_deg(theta);
    for (std::size_t s = 0; s < spec.samples; ++s) {
      const Point2 o = source_origin(grid, rays, true);
      const Hit hit = grid.first_hit(o, d, reach);
      tally.add(hit.found() ? hit.t / lambda : kInf, spec.t_max, width);
    }
    out.theta.push_back(std::move(tally));
  }
  {
    Tally iso(bins);
    for (std::size_t s = 0; s < spec.samples; ++s) {
      const Point2 o = source_origin(grid, rays, false);
      const double phi = 2.0 * std::numbers::pi * rays.uniform();
      const Hit hit = grid.first_hit(o, {std::cos(phi), std::sin(phi)}, reach);
      iso.add(hit.found() ? hit.t / lambda : kInf, spec.t_max, width);
    }
    out.iso = std::move(iso);
  }
  {
    Tally scat(bins);
    const double r = medium.radius;
    const auto n = static_cast<std::uint32_t>(medium.centers.size());
    for (std::size_t s = 0; s < spec.samples; ++s) {
      std::uint32_t idx = 0;
      Point2 w{};
      Point2 o{};
      for (int attempt = 0;; ++attempt) {
        if (attempt == 10000) fail("sim2d: every scatterer surface point tried lies inside another disk");
        idx = rays.uniform_below(n);
        const double phi = 2.0 * std::numbers::pi * rays.uniform();
        w = {std::cos(phi), std::sin(phi)};
        // Leave the disk along a chord with offset b uniform in (−r, r): lines through the disk
        // with direction ω are uniform in b (Cauchy–Crofton measure), i.e. exit points uniform on
        // the circle with cosine-weighted directions.
        const double b = r * (2.0 * rays.uniform() - 1.0);
        const double along = std::sqrt(std::max(0.0, r * r - b * b));
        const Point2 c = medium.centers[idx];
        o = {c.x - b * w.y + along * w.x, c.y + b * w.x + along * w.y};
        // Light leaves only the exposed boundary of the union of disks: an exit point buried in
        // an overlapping disk is not a scattering event (and would break p_Q = T_S/ℓ_S).
        if (!grid.inside_any(o, idx)) break;
      }
      const Hit hit = grid.first_hit(o, w, reach, idx);
      scat.add(hit.found() ? hit.t / lambda : kInf, spec.t_max, width);
    }
    out.scatterer = std::move(scat);
  }
  if (spec.boundary) {
    const double tb = spec.boundary_t * lambda;
    for (const double eta12 : spec.eta12) {
      // The second medium is the first translated by ω s (one draw per realization), s in
      // unit-square lengths: η₁,₂ = 0 moves it by about a domain length (uncorrelated).
      const double mean = (1.0 - eta12) * (1.0 - eta12);
      const double s_len = eta12 == 1.0 ? 0.0 : -std::log(shift_rng.uniform_open()) * mean;
      const double phi = 2.0 * std::numbers::pi * shift_rng.uniform();
      const Point2 shift{s_len * std::cos(phi), s_len * std::sin(phi)};
      Tally tally(bins);
      for (std::size_t s = 0; s < spec.samples; ++s) {
        const Point2 o = source_origin(grid, rays, true);
        const Hit first = grid.first_hit(o, {1.0, 0.0}, tb);
        if (first.found()) {
          tally.add(first.t / lambda, spec.t_max, width);
          continue;
        }
        // Medium 2 at x is medium 1 at x − shift.
        const Point2 o2{wrap_unit(o.x + tb - shift.x), wrap_unit(o.y - shift.y)};
        const Hit second = grid.first_hit(o2, {1.0, 0.0}, reach - tb);
        tally.add(second.found() ? spec.boundary_t + second.t / lambda : kInf, spec.t_max, width);
      }
      out.boundary.push_back(std::move(tally));
    }
  }
  return out;
}

}  // namespace weft::media2d
