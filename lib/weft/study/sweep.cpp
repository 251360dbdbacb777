// Accuracy against time: the reference beam, fewer rays, and coarse models (sweep.h).
#include "weft/study/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include <fmt/core.h>
#include <tbb/collaborative_call_once.h>
#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/dist/distributed.h"
#include "weft/fit/gamma_moments.h"
#include "weft/fit/local_fields.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/beam.h"
#include "weft/volume/block_lattice.h"
#include "weft/volume/downsample.h"
#include "weft/volume/grid.h"

namespace weft::study {
using namespace weft::fit;  // NOLINT(google-build-using-namespace)
namespace {

/// One coarse voxel along a ray: [a, b) in world distance from the entry, and its statistics.
struct Segment {
  double a = 0.0;
  double b = 0.0;
  double mean = 0.0;
  double var = 0.0;
};

/// The hazard composition of a coarse law (sweep.h): exponential voxels (variance ignored),
/// independent voxels (memory renewed at every voxel face) or memory from the ray's entry.
transmittance::MemoryRule memory_rule(CoarseLaw law) {
  return law == CoarseLaw::gamma_independent ? transmittance::MemoryRule::renewal : transmittance::MemoryRule::segment;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Runs `f` `reps` times; the median wall time in seconds.
template <typename F>
double timed(int reps, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return median(t);
}

/// A factor's coarse inputs, made once per process by whichever unit needs them first.
struct CoarseInputs {
  tbb::collaborative_once_flag grid_once;
  tbb::collaborative_once_flag fields_once;
  volume::Grid grid;  ///< volume::downsample (the exponential law's C̄)
  LocalFields fields;
};

double rms_stderr(const volume::TransmittanceCurve& c) {
  double s = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) s += c.stderr_abs(k) * c.stderr_abs(k);
  return c.size() > 0 ? std::sqrt(s / static_cast<double>(c.size())) : 0.0;
}

}  // namespace

std::vector<double> coarse_beam_log_t(const volume::Grid& mean, const volume::Grid* variance,
                                      const volume::IndexBox& fine_box, double fine_voxel, int factor,
                                      const std::array<double, 3>& direction, double sigma, CoarseLaw law) {
  require_positive("coarse beam: sigma", sigma);
  require_positive("coarse beam: fine voxel size", fine_voxel);
  if (factor < 1) fail("coarse beam: factor must be >= 1, got {}", factor);
  const int axis = volume::beam_axis(direction);
  if (axis < 0) fail("coarse beam: {} is not an axis direction", volume::direction_label(direction));
  if (fine_box.empty()) fail("coarse beam: the fine active box is empty");
  if (law != CoarseLaw::exponential && variance == nullptr) fail("coarse beam: a gamma law needs a variance grid");
  const double coarse_h = fine_voxel * factor;
  for (const volume::Grid* g : {&mean, variance}) {
    if (g != nullptr && std::abs(g->voxel_size() - coarse_h) > 1e-9 * coarse_h) {
      fail("coarse beam: grid '{}' has voxel size {}, expected {} x {}", g->name(), g->voxel_size(), factor,
           fine_voxel);
    }
  }
  const bool reverse = direction[static_cast<std::size_t>(axis)] < 0.0;
  const int ua = (axis + 1) % 3;
  const int va = (axis + 2) % 3;
  const std::int64_t f = factor;
  const auto fext = fine_box.extent();
  const std::int64_t n = fext[static_cast<std::size_t>(axis)];
  // The coarse grids' blocks are anchored at the fine box's lower corner (volume/block_lattice.h).
  const volume::BlockLattice lattice = volume::block_lattice(fine_box, factor);
  const std::int64_t cu0 = 0;
  const std::int64_t cu1 = lattice.block_of(ua, fine_box.max[ua]);
  const std::int64_t cv0 = 0;
  const std::int64_t cv1 = lattice.block_of(va, fine_box.max[va]);
  const std::int64_t ca0 = 0;
  const std::int64_t ca1 = lattice.block_of(axis, fine_box.max[axis]);
  const std::int64_t nu = cu1 - cu0 + 1;
  const std::int64_t nv = cv1 - cv0 + 1;
  const auto K = static_cast<std::size_t>(n) + 1;
  // A coarse column stands for the fine columns of the fine face it covers.
  const auto overlap = [&](std::int64_t c, int ax) {
    const std::int64_t lo = std::max<std::int64_t>(lattice.first_voxel(ax, c), fine_box.min[ax]);
    const std::int64_t hi = std::min<std::int64_t>(lattice.first_voxel(ax, c) + f - 1, fine_box.max[ax]);
    return static_cast<double>(std::max<std::int64_t>(0, hi - lo + 1));
  };
  const auto cols = static_cast<std::size_t>(nu * nv);
  std::vector<double> weight(cols);
  double wsum = 0.0;
  for (std::int64_t iu = 0; iu < nu; ++iu) {
    for (std::int64_t iv = 0; iv < nv; ++iv) {
      const double w = overlap(cu0 + iu, ua) * overlap(cv0 + iv, va);
      weight[static_cast<std::size_t>(iu * nv + iv)] = w;
      wsum += w;
    }
  }
  // H[col·K + k] = −log T of the column at t_k, every element written below (not zeroed first: at
  // the finest factor it is megabytes per call). row_lo[iu·K + k] = the smallest H[·, k] of the
  // columns of row iu, so the log-sum-exp below needs one pass over H, not two.
  const auto H = std::make_unique_for_overwrite<double[]>(cols * K);
  const auto row_lo = std::make_unique_for_overwrite<double[]>(static_cast<std::size_t>(nu) * K);
  parallel_units(static_cast<std::size_t>(nu), [&](std::size_t iu) {
    double* rlo = row_lo.get() + iu * K;
    std::fill(rlo, rlo + K, std::numeric_limits<double>::infinity());
    // Inactive voxels read 0, the grids' background (volume::VoxelReader).
    volume::VoxelReader macc(mean);
    std::optional<volume::VoxelReader> vacc;
    if (variance != nullptr) vacc.emplace(*variance);
    std::vector<Segment> segs;
    for (std::int64_t iv = 0; iv < nv; ++iv) {
      segs.clear();
      for (std::int64_t s = 0; s <= ca1 - ca0; ++s) {
        const std::int64_t ca = reverse ? ca1 - s : ca0 + s;
        std::array<int, 3> c{};
        c[static_cast<std::size_t>(axis)] = static_cast<int>(ca);
        c[static_cast<std::size_t>(ua)] = static_cast<int>(cu0 + static_cast<std::int64_t>(iu));
        c[static_cast<std::size_t>(va)] = static_cast<int>(cv0 + iv);
        Segment g;
        // Fine-index extent of the block along the ray, as distances from the entry face.
        const std::int64_t z0 = lattice.first_voxel(axis, ca);
        const std::int64_t z1 = z0 + f;
        const std::int64_t d0 = reverse ? fine_box.max[axis] + 1 - z1 : z0 - fine_box.min[axis];
        const std::int64_t d1 = reverse ? fine_box.max[axis] + 1 - z0 : z1 - fine_box.min[axis];
        g.a = fine_voxel * static_cast<double>(std::max<std::int64_t>(d0, 0));
        g.b = fine_voxel * static_cast<double>(std::min<std::int64_t>(d1, n));
        g.mean = static_cast<double>(macc.value(c));
        g.var = vacc ? static_cast<double>(vacc->value(c)) : 0.0;
        segs.push_back(g);
      }
      const std::size_t col = iu * static_cast<std::size_t>(nv) + static_cast<std::size_t>(iv);
      double* h = H.get() + col * K;
      // The coarse voxels' hazard with memory (transmittance::GammaHazard, the render medium's).
      transmittance::GammaHazard hazard(memory_rule(law), transmittance::Origin::source);
      const auto enter = [&](const Segment& g) {
        hazard.enter(sigma, g.mean, law == CoarseLaw::exponential ? 0.0 : g.var, g.a);
      };
      std::size_t s = 0;
      enter(segs[s]);
      for (std::size_t k = 0; k < K; ++k) {
        const double t = fine_voxel * static_cast<double>(k);
        while (s + 1 < segs.size() && t > segs[s].b) {
          hazard.advance(segs[s].a, segs[s].b);
          enter(segs[++s]);
        }
        h[k] = hazard.hazard() + hazard.piece(segs[s].a, std::max(segs[s].a, std::min(t, segs[s].b)));
      }
      if (weight[col] > 0.0) {
        for (std::size_t k = 0; k < K; ++k) rlo[k] = std::min(rlo[k], h[k]);
      }
    }
  });
  // log of the weighted mean of exp(−H) per depth, about the smallest H (log-sum-exp). The minimum
  // is exact in any grouping; each depth's sum is taken in column order (the bits of a depth-by-
  // depth loop), column by column: H is read in its own order, not one cache line per column and
  // depth, which on the finest factor's tens of thousands of columns cost more than the exponentials.
  std::vector<double> lo(K, std::numeric_limits<double>::infinity());
  for (std::size_t iu = 0; iu < static_cast<std::size_t>(nu); ++iu) {
    const double* rlo = row_lo.get() + iu * K;
    for (std::size_t k = 0; k < K; ++k) lo[k] = std::min(lo[k], rlo[k]);
  }
  std::vector<double> s(K, 0.0);
  for (std::size_t c = 0; c < cols; ++c) {
    if (!(weight[c] > 0.0)) continue;
    const double* h = H.get() + c * K;
    for (std::size_t k = 0; k < K; ++k) s[k] += weight[c] * std::exp(lo[k] - h[k]);
  }
  std::vector<double> log_t(K);
  for (std::size_t k = 0; k < K; ++k) log_t[k] = -lo[k] + std::log(s[k] / wsum);
  return log_t;
}

void mark_pareto(std::vector<SweepRow>& rows) {
  for (auto& r : rows) {
    r.pareto = true;
    for (const auto& o : rows) {
      if (&o == &r || o.axis != r.axis) continue;
      const bool no_worse = o.seconds() <= r.seconds() && o.accuracy_rms_t <= r.accuracy_rms_t;
      const bool better = o.seconds() < r.seconds() || o.accuracy_rms_t < r.accuracy_rms_t;
      if (no_worse && better) {
        r.pareto = false;
        break;
      }
    }
  }
}

Sweep sweep(const volume::Grid& grid, const SweepSpec& spec, ProgressSink& progress, dist::UnitStore* store) {
  require_positive("sweep: sigma", spec.sigma);
  if (grid.active_voxel_count() == 0) fail("sweep: grid '{}' has no active voxels", grid.name());
  if (spec.directions.empty()) fail("sweep: no beam directions");
  for (const auto& d : spec.directions) {
    if (volume::beam_axis(d) < 0) fail("sweep: beam {} is not along an axis", volume::direction_label(d));
  }
  for (int f : spec.factors) {
    if (f < 2 || f > 4096) fail("sweep: downsampling factor must be in 2..4096, got {}", f);
  }
  for (int s : spec.ray_strides) {
    if (s < 1 || s > 4096) fail("sweep: ray stride must be in 1..4096, got {}", s);
  }
  if (spec.repetitions < 1) fail("sweep: repetitions must be >= 1, got {}", spec.repetitions);
  const int reps = spec.repetitions;
  Sweep out;
  out.sigma = spec.sigma;
  out.voxel_size = grid.voxel_size();
  out.active_voxels = grid.active_voxel_count();
  out.repetitions = reps;
  const volume::IndexBox box = grid.active_bbox();
  const double h = grid.voxel_size();
  const std::array<std::pair<CoarseLaw, const char*>, 3> laws{{{CoarseLaw::exponential, "exponential"},
                                                               {CoarseLaw::gamma_independent, "gamma"},
                                                               {CoarseLaw::gamma_memory, "gamma-memory"}}};

  // Work units (spread over threads and MPI ranks, dist::run_units), in this order:
  //  - one per (downsampling factor, coarse input, timing repetition): makes the factor's local
  //    fields or its downsampled grid once and times it; the median over the repetitions is the
  //    rows' prepare_seconds. A factor's inputs are kept once per process, made by the first
  //    unit that needs them (tbb::collaborative_call_once; a repetition unit only times a
  //    computation of its own). The finest factor's fields are about a third of the run: as one
  //    unit, repetitions included, they bounded the run on any number of threads;
  //  - one per (factor, axis, kind of law), coarsest factor first: the exponential law's beam
  //    through the coarse grid, or the two gamma laws' beams through the local fields; the
  //    finest factor's last, so that its inputs are made (or being made) when they start;
  //  - one per (axis, ray stride): the ground truth with that share of the rays; stride 1 is the
  //    reference the errors are measured against (added as a unit even when it is not a row).
  //    Small and independent, they come last and fill the threads at the end.
  // Errors against the reference and the median times are computed afterwards, in the
  // reduction on rank 0. The rows do not depend on the order or on which unit made the inputs.
  std::vector<int> strides = spec.ray_strides;
  if (std::find(strides.begin(), strides.end(), 1) == strides.end()) strides.push_back(1);
  const std::size_t n_factors = spec.factors.size();
  const std::size_t n_axes = spec.directions.size();
  const std::size_t n_strides = strides.size();
  const auto n_reps = static_cast<std::size_t>(reps);
  const std::size_t n_prep = n_factors * 2 * n_reps;  // unit (f, gamma?, r) = (f·2 + !gamma)·reps + r
  const std::size_t n_models = n_factors * n_axes * 2;
  const std::size_t n_truth = n_axes * n_strides;  // unit n_prep + n_models + a·n_strides + i
  const std::size_t count = n_prep + n_models + n_truth;
  // Model unit n_prep + m: factor n_factors − 1 − m / (2·n_axes), axis m / 2 % n_axes, gamma m % 2.
  const auto model_unit = [&](std::size_t fi, std::size_t a, bool gamma) {
    return n_prep + ((n_factors - 1 - fi) * n_axes + a) * 2 + (gamma ? 1 : 0);
  };
  std::vector<CoarseInputs> inputs(n_factors);
  const auto make_fields = [&](std::size_t fi) {
    tbb::collaborative_call_once(inputs[fi].fields_once,
                                 [&] { inputs[fi].fields = local_fields(grid, spec.factors[fi]); });
  };
  const auto make_grid = [&](std::size_t fi) {
    tbb::collaborative_call_once(inputs[fi].grid_once,
                                 [&] { inputs[fi].grid = volume::downsample(grid, spec.factors[fi]); });
  };
  ProgressTask task(progress, "accuracy/time sweep", count);
  dist::UnitsOptions how;
  how.progress = &task;
  how.store = store;
  how.name = [&](std::size_t u) {
    if (u < n_prep) {
      return fmt::format("sweep unit {} (factor {} {}, repetition {})", u, spec.factors[u / n_reps / 2],
                         u / n_reps % 2 == 0 ? "local fields" : "coarse grid", u % n_reps + 1);
    }
    if (u >= n_prep + n_models) {
      const std::size_t a = (u - n_prep - n_models) / n_strides;
      const int stride = strides[(u - n_prep - n_models) % n_strides];
      return fmt::format("sweep unit {} (ground truth {}, ray stride {})", u,
                         volume::direction_label(spec.directions[a]), stride);
    }
    const std::size_t m = u - n_prep;
    return fmt::format("sweep unit {} (coarse {} models, factor {}, {})", u, m % 2 == 1 ? "gamma" : "exponential",
                       spec.factors[n_factors - 1 - m / 2 / n_axes],
                       volume::direction_label(spec.directions[m / 2 % n_axes]));
  };
  const std::vector<dist::Bytes> units = dist::run_units(
      count,
      [&](std::size_t u) {
        nlohmann::json j;
        if (u < n_prep) {
          const std::size_t fi = u / n_reps / 2;
          const bool gamma = u / n_reps % 2 == 0;
          const int f = spec.factors[fi];
          // The first repetition makes the kept inputs when no unit has yet; every repetition
          // times one computation of its own.
          const auto prepare = [&](LocalFields& fields, volume::Grid& coarse) {
            if (gamma) {
              fields = local_fields(grid, f);
            } else {
              coarse = volume::downsample(grid, f);
            }
          };
          bool made = false;
          double seconds = 0.0;
          if (u % n_reps == 0) {
            tbb::collaborative_call_once(gamma ? inputs[fi].fields_once : inputs[fi].grid_once, [&] {
              made = true;
              seconds = timed(1, [&] { prepare(inputs[fi].fields, inputs[fi].grid); });
            });
          }
          if (!made) {
            LocalFields fields;
            volume::Grid coarse;
            seconds = timed(1, [&] { prepare(fields, coarse); });
          }
          j["seconds"] = seconds;
        } else if (u >= n_prep + n_models) {
          const std::size_t a = (u - n_prep - n_models) / n_strides;
          volume::BeamSpec beam;
          beam.direction = spec.directions[a];
          beam.scale = spec.sigma;
          beam.seed = spec.seed;
          beam.column_stride = strides[(u - n_prep - n_models) % n_strides];
          volume::TransmittanceCurve c;
          j["seconds"] = timed(reps, [&] { c = volume::measure_beam(grid, beam); });
          j["depth"] = c.depth;
          j["log_t"] = c.log_t;
          j["rel_stderr"] = c.rel_stderr;
          j["rays"] = c.rays;
          j["direction"] = c.direction;
          j["method"] = c.method;
        } else {
          const std::size_t m = u - n_prep;
          const std::size_t fi = n_factors - 1 - m / 2 / n_axes;
          const std::array<double, 3>& d = spec.directions[m / 2 % n_axes];
          const bool gamma = m % 2 == 1;
          const int f = spec.factors[fi];
          const int axis = volume::beam_axis(d);
          const volume::Grid* mean = nullptr;
          const volume::Grid* var = nullptr;
          if (gamma) {
            make_fields(fi);
            mean = &inputs[fi].fields.mean;
            var = &inputs[fi].fields.variance[static_cast<std::size_t>(axis)];
          } else {
            make_grid(fi);
            mean = &inputs[fi].grid;
          }
          nlohmann::json beams = nlohmann::json::array();
          for (const auto& entry : laws) {
            const CoarseLaw law = entry.first;  // a plain variable: lambdas may not capture bindings (clang)
            if ((law != CoarseLaw::exponential) != gamma) continue;
            std::vector<double> log_t;
            const double seconds =
                timed(reps, [&] { log_t = coarse_beam_log_t(*mean, var, box, h, f, d, spec.sigma, law); });
            beams.push_back({{"log_t", log_t}, {"seconds", seconds}});
          }
          j["beams"] = std::move(beams);
        }
        return nlohmann::json::to_msgpack(j);
      },
      how);
  if (!dist::is_root()) return out;  // rank 0 holds every unit and reduces

  std::vector<nlohmann::json> unit(units.size());
  for (std::size_t u = 0; u < units.size(); ++u) unit[u] = nlohmann::json::from_msgpack(units[u]);
  // The median time to make a factor's local fields (gamma) or coarse grid over its repetitions.
  const auto prepare_seconds = [&](std::size_t fi, bool gamma) {
    std::vector<double> t;
    for (std::size_t r = 0; r < n_reps; ++r)
      t.push_back(unit[(fi * 2 + (gamma ? 0 : 1)) * n_reps + r].at("seconds").get<double>());
    return median(t);
  };
  for (std::size_t a = 0; a < spec.directions.size(); ++a) {
    const std::string label = volume::direction_label(spec.directions[a]);
    const auto curve = [&](int stride, double* seconds) {
      const std::size_t i =
          static_cast<std::size_t>(std::find(strides.begin(), strides.end(), stride) - strides.begin());
      const nlohmann::json& j = unit[n_prep + n_models + a * n_strides + i];
      volume::TransmittanceCurve c;
      j.at("depth").get_to(c.depth);
      j.at("log_t").get_to(c.log_t);
      j.at("rel_stderr").get_to(c.rel_stderr);
      c.rays = j.at("rays").get<std::uint64_t>();
      c.direction = j.at("direction").get<std::array<double, 3>>();
      c.method = j.at("method").get<std::string>();
      if (seconds != nullptr) *seconds = j.at("seconds").get<double>();
      return c;
    };
    const volume::TransmittanceCurve reference = curve(1, nullptr);
    for (int stride : spec.ray_strides) {
      SweepRow r;
      const volume::TransmittanceCurve c = curve(stride, &r.transport_seconds);
      r.axis = label;
      r.method = "ground-truth";
      r.ray_fraction = 1.0 / (static_cast<double>(stride) * static_cast<double>(stride));
      r.rays = c.rays;
      r.stderr_rms_t = rms_stderr(c);
      r.accuracy_rms_t = r.stderr_rms_t;
      // Error of the thinned ground truth against the reference (0 for the reference itself).
      const CurveError e = compare(reference, c.log_t);
      r.error_rms_t = e.rms_abs_t;
      r.error_max_t = e.max_abs_t;
      out.rows.push_back(r);
    }
    for (std::size_t fi = 0; fi < n_factors; ++fi) {
      for (std::size_t li = 0; li < laws.size(); ++li) {
        const bool gamma = laws[li].first != CoarseLaw::exponential;
        const nlohmann::json& j = unit[model_unit(fi, a, gamma)];
        const nlohmann::json& b = j.at("beams").at(gamma ? li - 1 : 0);  // laws: exponential, then the gammas
        const std::vector<double> log_t = b.at("log_t").get<std::vector<double>>();
        SweepRow r;
        r.transport_seconds = b.at("seconds").get<double>();
        // The reference's last depth is the box length, k·h up to rounding: same grid.
        const CurveError e = compare(reference, log_t);
        r.axis = label;
        r.method = laws[li].second;
        r.factor = spec.factors[fi];
        r.rays = reference.rays;
        r.error_rms_t = e.rms_abs_t;
        r.error_max_t = e.max_abs_t;
        r.accuracy_rms_t = e.rms_abs_t;
        r.prepare_seconds = prepare_seconds(fi, gamma);
        out.rows.push_back(r);
      }
    }
  }
  mark_pareto(out.rows);
  return out;
}

}  // namespace weft::study
