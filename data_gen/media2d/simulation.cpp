#include "data_gen/media2d/simulation.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include "data_gen/media2d/disk_grid.h"
#include "data_gen/media2d/law_fit.h"
#include "data_gen/media2d/realization_structure.h"
#include "data_gen/media2d/realization_tallies.h"
#include "data_gen/media2d/reciprocity.h"
#include "data_gen/media2d/tally.h"
#include "weft/core/distinct.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/core/number_name.h"
#include "weft/dist/distributed.h"

namespace weft::media2d {
namespace {

/// `value` (> limit) in 6 significant digits, or more until the text reads above `limit`: a
/// fixed precision can round a value just over a limit to the limit itself (100.025 at %.3g).
std::string above_limit(double value, double limit) {
  std::string text;
  for (int digits = 6; digits <= 17; ++digits) {
    text = fmt::format("{:.{}g}", value, digits);
    if (std::strtod(text.c_str(), nullptr) > limit) break;
  }
  return text;
}

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

double reduction_bytes(const SimulationSpec& spec) {
  // Every realization's tallies stay in memory until rank 0 reduces them: encoded (MessagePack,
  // at most 5 bytes a count and 9 an offset) for every η, then decoded (4 + 8 bytes a bin) and
  // as per-realization curve rows (8 bytes an edge) for one η at a time. In doubles: no overflow
  // for any count. Vector headers and allocations add about 64 bytes each.
  const auto bins = static_cast<double>(spec.bins);
  const double tallies = static_cast<double>(spec.thetas_deg.size() + 2 + (spec.boundary ? spec.eta12.size() : 0));
  const auto realizations = static_cast<double>(spec.realizations);
  const double encoded = realizations * static_cast<double>(spec.etas.size()) * (tallies * (14.0 * bins + 64.0) + 64.0);
  const double decoded = realizations * (tallies * (12.0 * bins + 64.0) + 128.0);
  const double rows = 2.0 * realizations * (8.0 * (bins + 1.0) + 64.0);
  return encoded + decoded + rows;
}

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
  if (spec.t_max * spec.mean_free_path > kMaxReach) {
    fail(
        "sim2d: t-max {} mean free paths of {} is {} domain lengths; at most {} are supported (the medium repeats "
        "every domain length: a longer ray measures its own periodic images, at a cost that grows with t-max)",
        spec.t_max, spec.mean_free_path, above_limit(spec.t_max * spec.mean_free_path, kMaxReach), kMaxReach);
  }
  if (spec.bins < 2 || spec.bins > 100'000) fail("sim2d: bins (--bins) must be in [2, 100000], got {}", spec.bins);
  for (const double theta : spec.thetas_deg) {
    if (!std::isfinite(theta)) fail("sim2d: source angle theta must be finite, got {}", theta);
  }
  // Each eta and angle is a case of its own: one given twice would be simulated again.
  require_distinct("sim2d: eta", spec.etas);
  // Angles are the same case when they give the same direction (modulo 360°: direction_deg).
  require_distinct(
      "sim2d: source angle theta", spec.thetas_deg,
      [&](std::size_t i) {
        const Point2 d = direction_deg(spec.thetas_deg[i]);
        return fmt::format("{} (direction ({:g}, {:g}), modulo 360 degrees)", spec.thetas_deg[i], d.x, d.y);
      },
      [](double theta) {
        const Point2 d = direction_deg(theta);
        return std::pair{d.x, d.y};
      });
  if (spec.structure_realizations > spec.realizations) {
    fail("sim2d: structure realizations must be <= the realizations per eta ({}), got {}", spec.realizations,
         spec.structure_realizations);
  }
  if (std::min(spec.structure_realizations, spec.realizations) > 0 && spec.structure_max_points < 16) {
    fail("sim2d: structure max points must be >= 16, got {}", spec.structure_max_points);
  }
  // The structure's stand-in (realization_structure) stretches a given step unit by √(n / n'),
  // so it meets max_step_unit before the medium does: refused here, not after the rays.
  if (std::min(spec.structure_realizations, spec.realizations) > 0 && spec.step_unit > 0.0) {
    for (const double eta : spec.etas) {
      const MediumSpec m{eta, spec.radius, spec.mean_free_path, spec.cluster_size, spec.step_unit};
      const std::size_t n = planned_count(m);
      if (n <= spec.structure_max_points) continue;
      const double stretched = spec.step_unit * std::sqrt(static_cast<double>(n) / spec.structure_max_points);
      if (stretched > max_step_unit(spec.radius))
        fail(
            "sim2d: step unit {} is {:.4g} on the structure's stand-in of {} particles (the medium of eta {} has {}), "
            "over {} for radius {}: lower the step unit or raise the structure's max points",
            spec.step_unit, stretched, spec.structure_max_points, eta, n,
            bound_text(max_step_unit(spec.radius), BoundSide::at_most), spec.radius);
    }
  }
  // Work units are keyed (η index << 40) | (realization << 4) (realization_tallies.h).
  if (spec.realizations > kMaxRealizations) {
    fail("sim2d: realizations must be <= {}, got {}", kMaxRealizations, spec.realizations);
  }
  if (spec.etas.size() >= (std::size_t{1} << 24U))
    fail("sim2d: at most {} etas, got {}", (1U << 24U) - 1U, spec.etas.size());
  const std::uint64_t budget = default_memory_budget();
  const double bytes = reduction_bytes(spec);
  if (bytes > static_cast<double>(budget)) {
    fail(
        "sim2d: {} realizations x {} eta(s) x {} bins would hold about {} of tallies for the reduction, over the "
        "memory budget of {} (fewer realizations or bins)",
        spec.realizations, spec.etas.size(), spec.bins, format_bytes(static_cast<std::uint64_t>(bytes)),
        format_bytes(budget));
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
    require_distinct("sim2d: eta12", spec.eta12);
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

  // The units, over ranks and threads: first the structure statistics of every η (each costs more
  // than a realization, so they start first and the realizations fill the threads around them),
  // then every η's realizations. One call for all η: no thread waits at the end of one η for the
  // next. The reduction below runs on rank 0 over the units in index order.
  const std::size_t etas = spec.etas.size();
  const std::size_t structure_units = etas * structure_count;
  ProgressTask task(progress, "sim2d units", structure_units + etas * spec.realizations);
  const auto structure_of = [&](std::size_t u) { return std::pair{u / structure_count, u % structure_count}; };
  const auto realization_of = [&](std::size_t u) {
    const std::size_t r = u - structure_units;
    return std::pair{r / spec.realizations, r % spec.realizations};
  };
  dist::UnitsOptions how;
  how.progress = &task;
  how.name = [&](std::size_t u) {
    if (u < structure_units) {
      const auto [e, j] = structure_of(u);
      return fmt::format("sim2d structure of realization {} of eta {}", j, spec.etas[e]);
    }
    const auto [e, j] = realization_of(u);
    return fmt::format("sim2d realization {} of eta {}", j, spec.etas[e]);
  };
  const std::vector<dist::Bytes> units = dist::run_units(
      structure_units + etas * spec.realizations,
      [&](std::size_t u) {
        if (u < structure_units) {
          const auto [e, j] = structure_of(u);
          return encode(realization_structure(spec, e, j));
        }
        const auto [e, j] = realization_of(u);
        return encode(trace_realization(spec, e, j));
      },
      how);
  if (!dist::is_root()) return result;

  for (std::size_t e = 0; e < etas; ++e) {
    const MediumSpec mspec{spec.etas[e], spec.radius, spec.mean_free_path, spec.cluster_size, spec.step_unit};
    std::vector<RealizationOut> outs;
    outs.reserve(spec.realizations);
    for (std::size_t j = 0; j < spec.realizations; ++j)
      outs.push_back(decode(units[structure_units + e * spec.realizations + j]));

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
    for (std::size_t j = 0; j < structure_count; ++j)
      er.structure.push_back(decode_structure(units[e * structure_count + j]));
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