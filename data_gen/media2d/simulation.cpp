#include "data_gen/media2d/simulation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <nlohmann/json.hpp>

#include "data_gen/media2d/disk_grid.h"
#include "data_gen/media2d/law_fit.h"
#include "weft/core/error.h"
#include "weft/dist/distributed.h"

namespace weft::media2d {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Free paths of one quantity in one realization, binned so that T, p and the exact bin
// integrals of T can be recovered: ∫_bin T = Δ·T(t_{k+1}) + Σ_{f in bin}(f − t_k)/M.
struct Tally {
  std::vector<std::uint32_t> counts;
  std::vector<double> offsets;
  std::uint32_t survivors = 0;
  double truncated_sum = 0.0;  // Σ min(f, t_max)
  std::uint32_t n = 0;

  Tally(std::size_t bins) : counts(bins, 0), offsets(bins, 0.0) {}
  void add(double f, double t_max, double width) {
    ++n;
    if (!(f < t_max)) {
      ++survivors;
      truncated_sum += t_max;
      return;
    }
    const auto k = std::min(counts.size() - 1, static_cast<std::size_t>(f / width));
    ++counts[k];
    offsets[k] += f - width * static_cast<double>(k);
    truncated_sum += f;
  }
  // T at the edges t_0 … t_bins.
  [[nodiscard]] std::vector<double> transmittance() const {
    std::vector<double> t(counts.size() + 1);
    double above = survivors;
    t[counts.size()] = above / n;
    for (std::size_t k = counts.size(); k-- > 0;) {
      above += counts[k];
      t[k] = above / n;
    }
    return t;
  }
  [[nodiscard]] std::vector<double> bin_probability() const {
    std::vector<double> p(counts.size());
    for (std::size_t k = 0; k < counts.size(); ++k) p[k] = static_cast<double>(counts[k]) / n;
    return p;
  }
  [[nodiscard]] std::vector<double> bin_integral(double width) const {
    const std::vector<double> t = transmittance();
    std::vector<double> integral(counts.size());
    for (std::size_t k = 0; k < counts.size(); ++k) integral[k] = width * t[k + 1] + offsets[k] / n;
    return integral;
  }
};

struct RealizationOut {
  std::vector<Tally> theta;
  std::optional<Tally> iso;
  std::optional<Tally> scatterer;
  std::vector<Tally> boundary;
  std::size_t perturbed = 0;
  std::size_t count = 0;
  std::optional<StructureStats> structure;
};

// A realization's result crosses ranks as MessagePack (dist::run_units): integers and doubles
// round-trip exactly, so the reduction on rank 0 sees the same numbers as in one process.
using nlohmann::json;

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
  j["structure"] = r.structure ? structure_json(*r.structure) : json(nullptr);
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
  if (!j.at("structure").is_null()) r.structure = structure_from(j.at("structure"));
  return r;
}

// Mean and standard error over realizations of per-realization vectors.
Curve mean_curve(const std::vector<std::vector<double>>& rows, std::size_t samples) {
  Curve c;
  const std::size_t m = rows.front().size();
  const auto r = static_cast<double>(rows.size());
  c.value.assign(m, 0.0);
  c.stderr_.assign(m, 0.0);
  for (const auto& row : rows) {
    for (std::size_t k = 0; k < m; ++k) c.value[k] += row[k];
  }
  for (auto& v : c.value) v /= r;
  if (rows.size() >= 2) {
    for (const auto& row : rows) {
      for (std::size_t k = 0; k < m; ++k) c.stderr_[k] += (row[k] - c.value[k]) * (row[k] - c.value[k]);
    }
    for (auto& v : c.stderr_) v = std::sqrt(v / (r - 1.0) / r);
  } else {
    // One realization: the binomial error of a fraction of `samples` rays.
    for (std::size_t k = 0; k < m; ++k) {
      const double p = std::clamp(c.value[k], 0.0, 1.0);
      c.stderr_[k] = std::sqrt(p * (1.0 - p) / static_cast<double>(samples));
    }
  }
  return c;
}

Curve transmittance_curve(const std::vector<const Tally*>& tallies, std::size_t samples) {
  std::vector<std::vector<double>> rows;
  rows.reserve(tallies.size());
  for (const Tally* t : tallies) rows.push_back(t->transmittance());
  return mean_curve(rows, samples);
}

Curve pdf_curve(const std::vector<const Tally*>& tallies, std::size_t samples, double width) {
  std::vector<std::vector<double>> rows;
  rows.reserve(tallies.size());
  for (const Tally* t : tallies) rows.push_back(t->bin_probability());
  Curve c = mean_curve(rows, samples);
  for (auto& v : c.value) v /= width;
  for (auto& v : c.stderr_) v /= width;
  return c;
}

std::pair<double, double> mean_truncated(const std::vector<const Tally*>& tallies, std::size_t samples) {
  std::vector<std::vector<double>> rows;
  for (const Tally* t : tallies) rows.push_back({t->truncated_sum / t->n});
  const Curve c = mean_curve(rows, samples);
  double se = c.stderr_[0];
  if (tallies.size() < 2) se = 0.0;
  return {c.value[0], se};
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
  const double a = theta_deg * std::numbers::pi / 180.0;
  return {std::cos(a), std::sin(a)};
}

Reciprocity check_reciprocity(const std::vector<const Tally*>& source, const std::vector<const Tally*>& scatterer,
                              std::size_t samples, const SimulationResult& result) {
  Reciprocity rec;
  const double width = result.edges[1] - result.edges[0];
  const auto [ell, ell_se] = mean_truncated(scatterer, samples);
  rec.ell_s = ell;
  rec.ell_s_stderr = ell_se;
  rec.tail_t_s = transmittance_curve(scatterer, samples).value.back();
  std::vector<std::vector<double>> p_rows;
  std::vector<std::vector<double>> i_rows;
  for (std::size_t j = 0; j < source.size(); ++j) {
    p_rows.push_back(source[j]->bin_probability());
    i_rows.push_back(scatterer[j]->bin_integral(width));
  }
  const Curve p_mean = mean_curve(p_rows, samples);
  const Curve i_mean = mean_curve(i_rows, samples);
  // Per realization D_k = P_Q,k − c·I_S,k keeps the correlation of both estimates within a medium.
  auto differences = [&](double c) {
    std::vector<std::vector<double>> rows;
    for (std::size_t j = 0; j < p_rows.size(); ++j) {
      std::vector<double> d(p_rows[j].size());
      for (std::size_t k = 0; k < d.size(); ++k) d[k] = p_rows[j][k] - c * i_rows[j][k];
      rows.push_back(std::move(d));
    }
    return mean_curve(rows, samples);
  };
  // c = 1/ℓ_S by weighted least squares, so a tail of T_S beyond t_max (which the truncated
  // integral misses) does not masquerade as a violation; two passes settle the weights.
  // Bins where the source free paths counted fewer than 20 times over all realizations are left
  // out: there the spread over realizations is not a Gaussian error.
  const double total = static_cast<double>(samples * source.size());
  auto usable = [&](std::size_t k, const Curve& d) { return d.stderr_[k] > 0.0 && p_mean.value[k] * total >= 20.0; };
  double c = ell > 0.0 ? 1.0 / ell : 1.0;
  double c_se = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    const Curve d = differences(c);
    double num = 0.0;
    double den = 0.0;
    for (std::size_t k = 0; k < d.value.size(); ++k) {
      if (!usable(k, d)) continue;
      const double w = 1.0 / (d.stderr_[k] * d.stderr_[k]);
      num += w * p_mean.value[k] * i_mean.value[k];
      den += w * i_mean.value[k] * i_mean.value[k];
    }
    if (den > 0.0) {
      c = num / den;
      c_se = 1.0 / std::sqrt(den);
    }
  }
  rec.ell_s_fit = 1.0 / c;
  rec.ell_s_fit_stderr = c_se / (c * c);
  const Curve diff = differences(c);
  rec.residual = diff.value;
  rec.residual_stderr = diff.stderr_;
  std::size_t used = 0;
  for (std::size_t k = 0; k < diff.value.size(); ++k) {
    if (!usable(k, diff)) continue;
    const double z = diff.value[k] / diff.stderr_[k];
    rec.chi2 += z * z;
    ++used;
    if (std::abs(z) > rec.max_abs_z) {
      rec.max_abs_z = std::abs(z);
      rec.max_abs_z_t = result.centres[k];
    }
  }
  rec.dof = used > 1 ? used - 1 : 0;
  return rec;
}

// Work unit of (η index, realization); the low 4 bits select the stream's purpose.
std::uint64_t unit_key(std::size_t eta_index, std::size_t realization) {
  return (static_cast<std::uint64_t>(eta_index) << 40U) | (static_cast<std::uint64_t>(realization) << 4U);
}

}  // namespace

Medium realization(const SimulationSpec& spec, std::size_t eta_index, std::size_t index) {
  if (eta_index >= spec.etas.size()) fail("sim2d: eta index {} out of range", eta_index);
  const MediumSpec mspec{spec.etas[eta_index], spec.radius, spec.mean_free_path, spec.cluster_size, spec.step_unit};
  Pcg32 gen = stream_for(spec.seed, unit_key(eta_index, index));
  return generate(mspec, gen);
}

void validate(const SimulationSpec& spec) {
  if (spec.etas.empty()) fail("sim2d: at least one eta is needed");
  for (const double eta : spec.etas) {
    MediumSpec m{eta, spec.radius, spec.mean_free_path, spec.cluster_size, spec.step_unit};
    validate(m);
  }
  if (spec.realizations == 0) fail("sim2d: realizations must be >= 1, got 0");
  if (spec.samples == 0) fail("sim2d: samples per realization must be >= 1, got 0");
  if (spec.samples > 100'000'000) fail("sim2d: samples per realization must be <= 1e8, got {}", spec.samples);
  if (!std::isfinite(spec.t_max) || spec.t_max <= 0.0) fail("sim2d: t-max must be > 0, got {}", spec.t_max);
  if (spec.bins < 2 || spec.bins > 100'000) fail("sim2d: bins must be in [2, 100000], got {}", spec.bins);
  for (const double theta : spec.thetas_deg) {
    if (!std::isfinite(theta)) fail("sim2d: source angle theta must be finite, got {}", theta);
  }
  if (spec.boundary) {
    if (!std::isfinite(spec.boundary_t) || spec.boundary_t <= 0.0 || spec.boundary_t >= spec.t_max) {
      fail("sim2d: boundary distance must be in (0, t-max = {}), got {}", spec.t_max, spec.boundary_t);
    }
    if (spec.eta12.empty()) fail("sim2d: the boundary experiment needs at least one eta12");
    for (const double e : spec.eta12) {
      if (!std::isfinite(e) || e < 0.0 || e > 1.0) {
        fail("sim2d: eta12 (correlation of the second medium with the first) must be in [0, 1], got {}", e);
      }
    }
  }
}

std::vector<double> source_free_paths(const Medium& medium, double mean_free_path, double theta_deg,
                                      std::size_t samples, double t_max, Pcg32& rng) {
  const DiskGrid grid(medium);
  const Point2 d = direction_deg(theta_deg);
  std::vector<double> paths;
  paths.reserve(samples);
  for (std::size_t s = 0; s < samples; ++s) {
    const Point2 o = source_origin(grid, rng, true);
    const Hit hit = grid.first_hit(o, d, t_max * mean_free_path);
    paths.push_back(hit.found() ? hit.t / mean_free_path : kInf);
  }
  return paths;
}

SimulationResult simulate(const SimulationSpec& spec, ProgressSink& progress) {
  validate(spec);
  SimulationResult result;
  result.spec = spec;
  const std::size_t bins = spec.bins;
  const double width = spec.t_max / static_cast<double>(bins);
  result.edges.resize(bins + 1);
  result.centres.resize(bins);
  for (std::size_t k = 0; k <= bins; ++k) result.edges[k] = width * static_cast<double>(k);
  for (std::size_t k = 0; k < bins; ++k) result.centres[k] = width * (static_cast<double>(k) + 0.5);
  const double lambda = spec.mean_free_path;
  const double reach = spec.t_max * lambda;
  if (reach > 1.0 + 1e-12) {
    result.warnings.push_back(fmt::format(
        "rays reach {:.3g} domain lengths (t-max x mean free path > 1): they may revisit their own path in the "
        "periodic square, which biases the tails",
        reach));
  }
  const std::size_t structure_count = std::min(spec.structure_realizations, spec.realizations);
  if (structure_count > 0 && spec.structure_max_points < 16) {
    fail("sim2d: structure max points must be >= 16, got {}", spec.structure_max_points);
  }

  ProgressTask task(progress, "sim2d realizations", spec.etas.size() * spec.realizations);
  for (std::size_t e = 0; e < spec.etas.size(); ++e) {
    const MediumSpec mspec{spec.etas[e], spec.radius, spec.mean_free_path, spec.cluster_size, spec.step_unit};
    // Realizations are the units spread over ranks (and threads); the reduction below runs on
    // rank 0 over all of them in index order.
    dist::UnitsOptions how;
    how.progress = &task;
    how.name = [&](std::size_t j) { return fmt::format("sim2d realization {} of eta {}", j, spec.etas[e]); };
    const std::vector<dist::Bytes> units = dist::run_units(
        spec.realizations,
        [&](std::size_t j) {
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
          if (j < structure_count) {
            if (medium.centers.size() <= spec.structure_max_points) {
              out.structure = structure_stats(medium, j);
            } else {
              // Stand-in with n' = structure_max_points particles: λ' solves n' = 1/(2rλ' + πr²).
              MediumSpec small = mspec;
              const double n_small = static_cast<double>(spec.structure_max_points);
              small.mean_free_path =
                  (1.0 / n_small - std::numbers::pi * spec.radius * spec.radius) / (2.0 * spec.radius);
              if (spec.step_unit > 0.0)
                small.step_unit = spec.step_unit * std::sqrt(static_cast<double>(medium.centers.size()) / n_small);
              Pcg32 stand_in_rng = stream_for(spec.seed, base | 3U);
              out.structure = structure_stats(generate(small, stand_in_rng), j);
              out.structure->note = fmt::format(
                  "measured on a stand-in realization of the same generator with {} particles (the medium has {}); "
                  "distances in units of the mean spacing",
                  out.structure->points, medium.centers.size());
            }
          }
          return encode(out);
        },
        how);
    if (!dist::is_root()) continue;
    std::vector<RealizationOut> outs;
    outs.reserve(units.size());
    for (const auto& b : units) outs.push_back(decode(b));

    EtaResult er;
    er.eta = spec.etas[e];
    er.generator = spec.etas[e] < 0.0 ? "lattice" : (spec.etas[e] == 0.0 ? "poisson" : "random-walk");
    er.particles = outs.front().count;
    er.santalo_mfp = santalo_mean_free_path(er.particles, spec.radius) / lambda;
    er.exact_poisson_mfp = 1.0 / (2.0 * static_cast<double>(er.particles) * spec.radius) / lambda;
    er.step_unit = step_unit(mspec);
    if (spec.etas[e] < 0.0) er.lattice = lattice_layout(mspec);
    double perturbed = 0.0;
    for (const auto& o : outs) perturbed += static_cast<double>(o.perturbed) / static_cast<double>(o.count);
    er.perturbed_fraction = perturbed / static_cast<double>(outs.size());

    auto collect = [&](auto pick) {
      std::vector<const Tally*> v;
      v.reserve(outs.size());
      for (const auto& o : outs) v.push_back(pick(o));
      return v;
    };
    for (std::size_t a = 0; a < spec.thetas_deg.size(); ++a) {
      const auto tallies = collect([a](const RealizationOut& o) { return &o.theta[a]; });
      er.t_q.push_back(transmittance_curve(tallies, spec.samples));
      er.p_q.push_back(pdf_curve(tallies, spec.samples, width));
    }
    const auto iso = collect([](const RealizationOut& o) { return &*o.iso; });
    const auto scat = collect([](const RealizationOut& o) { return &*o.scatterer; });
    er.t_q_iso = transmittance_curve(iso, spec.samples);
    er.p_q_iso = pdf_curve(iso, spec.samples, width);
    er.t_s = transmittance_curve(scat, spec.samples);
    er.p_s = pdf_curve(scat, spec.samples, width);
    std::tie(er.ell_q_iso, er.ell_q_iso_stderr) = mean_truncated(iso, spec.samples);
    er.reciprocity = check_reciprocity(iso, scat, spec.samples, result);
    if (spec.boundary) {
      for (std::size_t b = 0; b < spec.eta12.size(); ++b) {
        const auto tallies = collect([b](const RealizationOut& o) { return &o.boundary[b]; });
        er.boundary.push_back(
            {spec.eta12[b], transmittance_curve(tallies, spec.samples), pdf_curve(tallies, spec.samples, width)});
      }
    }
    for (const auto& o : outs) {
      if (o.structure) er.structure.push_back(*o.structure);
    }
    const double floor = 1.0 / static_cast<double>(spec.samples * spec.realizations);
    for (const auto& [name, curve] : {std::pair<std::string, const Curve*>{"T_Q_iso", &er.t_q_iso},
                                      std::pair<std::string, const Curve*>{"T_S", &er.t_s}}) {
      for (const char* law : {"exponential", "gamma", "linear", "gamma-path"}) {
        LawFit fit = fit_law(law, result.edges, curve->value, curve->stderr_, floor);
        fit.curve = name;
        er.fits.push_back(std::move(fit));
      }
    }
    // The same laws on the free-path histograms (nearly independent bins): what law selection
    // compares (law_fit.h, select_law).
    const double bin_width = result.edges[1] - result.edges[0];
    for (const auto& [name, curve] : {std::pair<std::string, const Curve*>{"p_Q_iso", &er.p_q_iso},
                                      std::pair<std::string, const Curve*>{"p_S", &er.p_s}}) {
      for (const char* law : {"exponential", "gamma", "linear", "gamma-path"}) {
        LawFit fit = fit_law_binned(law, result.edges, curve->value, curve->stderr_, floor / bin_width);
        fit.curve = name;
        er.fits.push_back(std::move(fit));
      }
    }
    result.etas.push_back(std::move(er));
  }
  return result;
}

}  // namespace weft::media2d
