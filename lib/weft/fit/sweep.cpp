// Accuracy against time: the reference beam, fewer rays, and coarse models (sweep.h).
#include "weft/fit/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "weft/core/error.h"
#include "weft/core/floor_div.h"
#include "weft/core/parallel.h"
#include "weft/fit/fit.h"
#include "weft/volume/beam.h"
#include "weft/volume/downsample.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::fit {
namespace {

/// One coarse voxel along a ray: [a, b) in world distance from the entry, and its statistics.
struct Segment {
  double a = 0.0;
  double b = 0.0;
  double mean = 0.0;
  double var = 0.0;
};

/// −log T contributed by segment `g` over [g.a, t] (t ≤ g.b), per law (sweep.h).
double segment_depth(const Segment& g, double t, double sigma, CoarseLaw law) {
  const double len = t - g.a;
  if (!(len > 0.0) || !(g.mean > 0.0)) return 0.0;
  if (law == CoarseLaw::exponential || !(g.var > 0.0)) return sigma * g.mean * len;
  const double alpha = g.mean * g.mean / g.var;
  const double kappa = sigma * g.var / g.mean;  // σ/β
  if (law == CoarseLaw::gamma_independent) return alpha * std::log1p(kappa * len);
  return alpha * (std::log1p(kappa * t) - std::log1p(kappa * g.a));
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
  const std::int64_t cu0 = floor_div(fine_box.min[ua], f);
  const std::int64_t cu1 = floor_div(fine_box.max[ua], f);
  const std::int64_t cv0 = floor_div(fine_box.min[va], f);
  const std::int64_t cv1 = floor_div(fine_box.max[va], f);
  const std::int64_t ca0 = floor_div(fine_box.min[axis], f);
  const std::int64_t ca1 = floor_div(fine_box.max[axis], f);
  const std::int64_t nu = cu1 - cu0 + 1;
  const std::int64_t nv = cv1 - cv0 + 1;
  const auto K = static_cast<std::size_t>(n) + 1;
  // A coarse column stands for the fine columns of the fine face it covers.
  const auto overlap = [&](std::int64_t c, int ax) {
    const std::int64_t lo = std::max<std::int64_t>(c * f, fine_box.min[ax]);
    const std::int64_t hi = std::min<std::int64_t>(c * f + f - 1, fine_box.max[ax]);
    return static_cast<double>(std::max<std::int64_t>(0, hi - lo + 1));
  };
  const auto cols = static_cast<std::size_t>(nu * nv);
  std::vector<double> H(cols * K);  // H[col·K + k] = −log T of the column at t_k
  const auto& mvdb = *mean.impl().grid;
  parallel_units(static_cast<std::size_t>(nu), [&](std::size_t iu) {
    auto macc = mvdb.getConstAccessor();
    std::unique_ptr<openvdb::FloatGrid::ConstAccessor> vacc;
    if (variance != nullptr)
      vacc = std::make_unique<openvdb::FloatGrid::ConstAccessor>(variance->impl().grid->getConstAccessor());
    std::vector<Segment> segs;
    for (std::int64_t iv = 0; iv < nv; ++iv) {
      segs.clear();
      for (std::int64_t s = 0; s <= ca1 - ca0; ++s) {
        const std::int64_t ca = reverse ? ca1 - s : ca0 + s;
        openvdb::Coord c;
        c[axis] = static_cast<int>(ca);
        c[ua] = static_cast<int>(cu0 + static_cast<std::int64_t>(iu));
        c[va] = static_cast<int>(cv0 + iv);
        Segment g;
        // Fine-index extent of the block along the ray, as distances from the entry face.
        const std::int64_t z0 = ca * f;
        const std::int64_t z1 = ca * f + f;
        const std::int64_t d0 = reverse ? fine_box.max[axis] + 1 - z1 : z0 - fine_box.min[axis];
        const std::int64_t d1 = reverse ? fine_box.max[axis] + 1 - z0 : z1 - fine_box.min[axis];
        g.a = fine_voxel * static_cast<double>(std::max<std::int64_t>(d0, 0));
        g.b = fine_voxel * static_cast<double>(std::min<std::int64_t>(d1, n));
        g.mean = static_cast<double>(macc.getValue(c));
        g.var = vacc ? static_cast<double>(vacc->getValue(c)) : 0.0;
        segs.push_back(g);
      }
      double* h = H.data() + (iu * static_cast<std::size_t>(nv) + static_cast<std::size_t>(iv)) * K;
      std::size_t s = 0;
      double done = 0.0;
      for (std::size_t k = 0; k < K; ++k) {
        const double t = fine_voxel * static_cast<double>(k);
        while (s + 1 < segs.size() && t > segs[s].b) {
          done += segment_depth(segs[s], segs[s].b, sigma, law);
          ++s;
        }
        h[k] = done + segment_depth(segs[s], std::min(t, segs[s].b), sigma, law);
      }
    }
  });
  // log of the weighted mean of exp(−H) per depth, about the smallest H (log-sum-exp).
  std::vector<double> weight(cols);
  double wsum = 0.0;
  for (std::int64_t iu = 0; iu < nu; ++iu) {
    for (std::int64_t iv = 0; iv < nv; ++iv) {
      const double w = overlap(cu0 + iu, ua) * overlap(cv0 + iv, va);
      weight[static_cast<std::size_t>(iu * nv + iv)] = w;
      wsum += w;
    }
  }
  std::vector<double> log_t(K);
  for (std::size_t k = 0; k < K; ++k) {
    double lo = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < cols; ++c) {
      if (weight[c] > 0.0) lo = std::min(lo, H[c * K + k]);
    }
    double s = 0.0;
    for (std::size_t c = 0; c < cols; ++c) {
      if (weight[c] > 0.0) s += weight[c] * std::exp(lo - H[c * K + k]);
    }
    log_t[k] = -lo + std::log(s / wsum);
  }
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

Sweep sweep(const volume::Grid& grid, const SweepSpec& spec, ProgressSink& progress) {
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

  ProgressTask task(progress, "accuracy/time sweep",
                    spec.factors.size() + spec.directions.size() * (spec.ray_strides.size() + 3 * spec.factors.size()));
  // Coarse inputs, shared by the axes: the downsampled grid (exponential) and the local fields
  // (gamma), each with the median time it takes to make.
  struct Coarse {
    int factor = 1;
    volume::Grid grid;
    double grid_seconds = 0.0;
    LocalFields fields;
    double fields_seconds = 0.0;
  };
  std::vector<Coarse> coarse;
  for (int f : spec.factors) {
    Coarse c;
    c.factor = f;
    c.grid_seconds = timed(reps, [&] { c.grid = volume::downsample(grid, f); });
    c.fields_seconds = timed(reps, [&] { c.fields = local_fields(grid, f); });
    coarse.push_back(std::move(c));
    task.step();
  }

  for (const auto& d : spec.directions) {
    const int axis = volume::beam_axis(d);
    const std::string label = volume::direction_label(d);
    volume::BeamSpec beam;
    beam.direction = d;
    beam.scale = spec.sigma;
    beam.seed = spec.seed;
    volume::TransmittanceCurve reference;
    std::vector<std::pair<SweepRow, volume::TransmittanceCurve>> thinned;
    for (int stride : spec.ray_strides) {
      beam.column_stride = stride;
      volume::TransmittanceCurve c;
      SweepRow r;
      r.transport_seconds = timed(reps, [&] { c = volume::measure_beam(grid, beam); });
      r.axis = label;
      r.method = "ground-truth";
      r.ray_fraction = 1.0 / (static_cast<double>(stride) * static_cast<double>(stride));
      r.rays = c.rays;
      r.stderr_rms_t = rms_stderr(c);
      r.accuracy_rms_t = r.stderr_rms_t;
      if (stride == 1) reference = c;
      thinned.emplace_back(r, std::move(c));
      task.step();
    }
    if (reference.size() == 0) {
      beam.column_stride = 1;
      reference = volume::measure_beam(grid, beam);
    }
    // Errors of the thinned ground truths against the reference (0 for the reference itself).
    for (auto& [r, c] : thinned) {
      const CurveError e = compare(reference, c.log_t);
      r.error_rms_t = e.rms_abs_t;
      r.error_max_t = e.max_abs_t;
      out.rows.push_back(r);
    }
    for (const auto& c : coarse) {
      const std::array<std::pair<CoarseLaw, const char*>, 3> laws{{{CoarseLaw::exponential, "exponential"},
                                                                   {CoarseLaw::gamma_independent, "gamma"},
                                                                   {CoarseLaw::gamma_memory, "gamma-memory"}}};
      for (const auto& [law, name] : laws) {
        const bool gamma = law != CoarseLaw::exponential;
        const volume::Grid& mean = gamma ? c.fields.mean : c.grid;
        const volume::Grid* var = gamma ? &c.fields.variance[static_cast<std::size_t>(axis)] : nullptr;
        std::vector<double> log_t;
        SweepRow r;
        r.transport_seconds =
            timed(reps, [&] { log_t = coarse_beam_log_t(mean, var, box, h, c.factor, d, spec.sigma, law); });
        // The reference's last depth is the box length, k·h up to rounding: same grid.
        const CurveError e = compare(reference, log_t);
        r.axis = label;
        r.method = name;
        r.factor = c.factor;
        r.rays = reference.rays;
        r.error_rms_t = e.rms_abs_t;
        r.error_max_t = e.max_abs_t;
        r.accuracy_rms_t = e.rms_abs_t;
        r.prepare_seconds = gamma ? c.fields_seconds : c.grid_seconds;
        out.rows.push_back(r);
        task.step();
      }
    }
  }
  mark_pareto(out.rows);
  return out;
}

}  // namespace weft::fit
