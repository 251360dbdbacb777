// Predictive models of axis beams from window statistics and local fields (fit/models.h).
#include "weft/fit/models.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/fit/local_models.h"
#include "weft/fit/moments.h"
#include "weft/fit/window_stats.h"
#include "weft/transmittance/gamma_mixture.h"
#include "weft/transmittance/gap_gamma.h"
#include "weft/transmittance/registry.h"
#include "weft/transmittance/shape_rate.h"
#include "weft/volume/beam.h"
#include "weft/volume/columns.h"

namespace weft::fit {
namespace {

using detail::BlockStats;
using detail::kShards;
using detail::log_sum_exp_mean;
using detail::Memory;
using detail::Sums;

// Histogram of window means for Eq. 16: kSub bins per octave over kOctaves octaves of m (2^-41
// to 2^23; mean concentrations and extinctions in 1/mm lie far inside).
constexpr int kSub = 128;
constexpr int kOctaves = 64;
constexpr int kMinExponent = -40;
constexpr int kBins = kSub * kOctaves;

using GroupKey = std::pair<std::int64_t, std::int64_t>;

struct Group {
  Sums windows;
  double rays = 0.0;
};

/// Everything one pass over the windows of length w along the columns gives.
struct WindowSummary {
  Sums all;
  Moments moments;  ///< the same windows, Welford: the window statistics validate reports
  Sums nonzero;
  double zeros = 0.0;
  std::map<GroupKey, Group> groups;
  std::vector<double> bin_count;
  std::vector<double> bin_sum;
};

/// The histogram bin of a window mean m > 0 for Eq. 16: kSub bins per octave of m (the octave
/// from frexp's exponent), so no range has to be known before the pass; means below the lowest
/// octave share bin 0, above the highest the last bin (each bin is evaluated at its own mean).
int bin_of(double m) {
  int e = 0;
  const double f = std::frexp(m, &e);  // m = f·2^e, f in [0.5, 1)
  if (e < kMinExponent) return 0;
  if (e >= kMinExponent + kOctaves) return kBins - 1;
  return (e - kMinExponent) * kSub + std::min(kSub - 1, static_cast<int>((f - 0.5) * 2.0 * kSub));
}

/// One pass over every window of w voxels of every column along the reader's axis; groups are
/// transverse cells of `cell` voxels anchored at the active box's lower corner (docs/validate.md
/// "Blocks anchored to the cloth"), so the same voxels at another index origin give the same
/// groups.
WindowSummary summarize(const volume::ColumnReader& reader, int w, int cell, ProgressSink& progress) {
  const int n = static_cast<int>(reader.box().extent()[reader.axis()]);
  const std::int64_t u_lo = reader.box().min[static_cast<std::size_t>((reader.axis() + 1) % 3)];
  const std::int64_t v_lo = reader.box().min[static_cast<std::size_t>((reader.axis() + 2) % 3)];
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  const int positions = n - w + 1;
  std::vector<WindowSummary> parts(shards);
  ProgressTask task(progress, fmt::format("window statistics {}", "xyz"[reader.axis()]), units);
  parallel_units(shards, [&](std::size_t shard) {
    volume::ColumnTile tile;
    std::vector<double> prefix(static_cast<std::size_t>(n) + 1);
    auto& part = parts[shard];
    part.bin_count.assign(kBins, 0.0);
    part.bin_sum.assign(kBins, 0.0);
    for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
      reader.read(unit, tile);
      for (int iu = 0; iu < tile.nu; ++iu) {
        for (int iv = 0; iv < tile.nv; ++iv) {
          const float* col = tile.column(iu, iv);
          prefix[0] = 0.0;
          for (int k = 0; k < n; ++k)
            prefix[static_cast<std::size_t>(k) + 1] = prefix[static_cast<std::size_t>(k)] + col[k];
          const GroupKey key{(tile.u0 + iu - u_lo) / cell, (tile.v0 + iv - v_lo) / cell};
          Group& g = part.groups[key];
          g.rays += 1.0;
          auto mean_at = [&](int s) {
            return (prefix[static_cast<std::size_t>(s + w)] - prefix[static_cast<std::size_t>(s)]) / w;
          };
          double column_sum = 0.0;
          for (int s = 0; s < positions; ++s) {
            const double m = mean_at(s);
            part.all.add(m);
            column_sum += m;
            g.windows.add(m);
            if (m > 0.0) {
              part.nonzero.add(m);
              const auto b = static_cast<std::size_t>(bin_of(m));
              part.bin_count[b] += 1.0;
              part.bin_sum[b] += m;
            } else {
              part.zeros += 1.0;
            }
          }
          if (positions > 0) {
            // The column's moments about its own mean (two passes over its windows, no
            // division per window), merged pairwise into the shard's (moments.h).
            Moments column;
            column.n = static_cast<std::uint64_t>(positions);
            column.mean = column_sum / positions;
            for (int s = 0; s < positions; ++s) {
              const double dev = mean_at(s) - column.mean;
              column.m2 += dev * dev;
            }
            part.moments.merge(column);
          }
        }
      }
      task.step();
    }
  });
  WindowSummary out;
  out.bin_count.assign(kBins, 0.0);
  out.bin_sum.assign(kBins, 0.0);
  for (const auto& p : parts) {
    out.all.merge(p.all);
    out.moments.merge(p.moments);
    out.nonzero.merge(p.nonzero);
    out.zeros += p.zeros;
    for (const auto& [k, g] : p.groups) {
      auto& dst = out.groups[k];
      dst.windows.merge(g.windows);
      dst.rays += g.rays;
    }
    for (int b = 0; b < kBins; ++b) {
      out.bin_count[static_cast<std::size_t>(b)] += p.bin_count[static_cast<std::size_t>(b)];
      out.bin_sum[static_cast<std::size_t>(b)] += p.bin_sum[static_cast<std::size_t>(b)];
    }
  }
  return out;
}

}  // namespace

namespace {
/// The registry law of gamma_log_t: gamma (mean extinction σC̄, α = C̄²/Var), the exponential
/// when Var = 0.
transmittance::LawPtr gamma_or_exponential(double sigma, double mean, double var) {
  transmittance::LawSpec spec;
  if (mean > 0.0 && var > 0.0) {
    spec.name = "gamma";
    spec.params = {{"mean_extinction", sigma * mean}, {"alpha", transmittance::gamma_shape_rate(mean, var).alpha}};
  } else {
    spec.name = "exponential";
    spec.params = {{"mu", sigma * std::max(0.0, mean)}};
  }
  return transmittance::make_law(spec);
}
}  // namespace

double gamma_log_t(double sigma, double mean, double var, double t) {
  if (!(mean > 0.0) || t == 0.0) return 0.0;
  if (!(var > 0.0)) return -sigma * mean * t;
  const auto [alpha, beta] = transmittance::gamma_shape_rate(mean, var);
  return -alpha * std::log1p(sigma * t / beta);
}

std::vector<PredictedModel> predict_axis(const volume::Grid& grid, const PredictionSpec& spec,
                                         const std::vector<double>& depths, ProgressSink& progress,
                                         ConcentrationStats* moments_out) {
  require_positive("predict: sigma", spec.sigma);
  if (!std::isfinite(spec.scale) || spec.scale < 0.0) fail("predict: scale must be >= 0, got {}", spec.scale);
  const int axis = volume::beam_axis(spec.direction);
  if (axis < 0) fail("predict: beam {} is not along an axis", volume::direction_label(spec.direction));
  if (grid.active_voxel_count() == 0) fail("predict: grid '{}' has no active voxels", grid.name());
  const bool reverse = spec.direction[static_cast<std::size_t>(axis)] < 0.0;
  const double h = grid.voxel_size();
  const volume::ColumnReader reader(grid, axis);
  const auto box = reader.box();
  const int n = static_cast<int>(box.extent()[static_cast<std::size_t>(axis)]);
  const int w = window_voxels(spec.scale, h, n);
  const double sigma = spec.sigma;
  const WindowSummary ws = summarize(reader, w, w, progress);
  if (moments_out != nullptr) {
    moments_out->mean = ws.moments.mean;
    moments_out->variance = ws.moments.variance();
    moments_out->samples = ws.moments.n;
    moments_out->window_voxels = w;
    moments_out->window = w * h;
  }
  std::vector<PredictedModel> out;
  auto add = [&](std::string name, std::string description, std::vector<std::pair<std::string, double>> params,
                 auto&& log_t_of, transmittance::LawPtr law = nullptr) {
    PredictedModel m;
    m.law = std::move(law);
    m.name = std::move(name);
    m.description = std::move(description);
    m.parameters = std::move(params);
    m.log_t.reserve(depths.size());
    for (std::size_t d = 0; d < depths.size(); ++d) m.log_t.push_back(log_t_of(d, depths[d]));
    out.push_back(std::move(m));
  };
  const double L = w * h;
  // The paper's law (Eq. 19–20) from all windows.
  {
    const double mean = ws.all.mean();
    const double var = ws.all.var();
    add(
        "gamma", "Eq. 19-20: gamma concentration from all windows of length L",
        {{"window", L},
         {"mean_concentration", mean},
         {"var_concentration", var},
         {"alpha", transmittance::gamma_shape_rate(mean, var).alpha},
         {"beta", transmittance::gamma_shape_rate(mean, var).beta}},
        [&](std::size_t, double t) { return gamma_log_t(sigma, mean, var, t); },
        gamma_or_exponential(sigma, mean, var));
  }
  // Eq. 16 with the empirical distribution (histogram bins at their own mean).
  {
    const double total = ws.all.n;
    std::vector<double> c;
    std::vector<double> p;
    if (ws.zeros > 0.0) {
      c.push_back(0.0);
      p.push_back(ws.zeros / total);
    }
    for (int b = 0; b < kBins; ++b) {
      const double cnt = ws.bin_count[static_cast<std::size_t>(b)];
      if (cnt > 0.0) {
        c.push_back(ws.bin_sum[static_cast<std::size_t>(b)] / cnt);
        p.push_back(cnt / total);
      }
    }
    std::vector<double> logs(c.size());
    add("empirical", "Eq. 16: mean over all windows of length L of exp(-sigma C_w t)",
        {{"window", L},
         {"windows", total},
         {"empty_fraction", ws.zeros / total},
         {"bins", static_cast<double>(c.size())}},
        [&](std::size_t, double t) {
          for (std::size_t i = 0; i < c.size(); ++i) logs[i] = -sigma * c[i] * t;
          return log_sum_exp_mean(logs, p);
        });
  }
  // Gap-aware gamma: empty windows see nothing, the others a gamma law.
  {
    const double f0 = ws.all.n > 0.0 ? ws.zeros / ws.all.n : 0.0;
    const double mean = ws.nonzero.mean();
    const double var = ws.nonzero.var();
    // The registry's gap-gamma law (one implementation of its stable log T); α = ∞ without variance.
    const std::shared_ptr<const transmittance::Law> gap_law =
        mean > 0.0 && f0 < 1.0 ? std::unique_ptr<transmittance::Law>(std::make_unique<transmittance::GapGamma>(
                                     f0, sigma * mean, transmittance::gamma_shape_rate(mean, var).alpha))
                               : std::unique_ptr<transmittance::Law>(std::make_unique<transmittance::GammaMixture>(
                                     std::vector<transmittance::GammaComponent>{{1.0, 0.0, INFINITY}}));
    add(
        "gap-gamma", "gap fraction f0 (empty windows of length L) plus a gamma law of the others",
        {{"window", L},
         {"gap_fraction", f0},
         {"mean_concentration", mean},
         {"var_concentration", var},
         {"alpha", transmittance::gamma_shape_rate(mean, var).alpha},
         {"beta", transmittance::gamma_shape_rate(mean, var).beta}},
        [&](std::size_t, double t) { return gap_law->log_transmittance(t); }, gap_law);
  }
  // Across the beam: a gamma law per transverse cell of side L, mixed by rays.
  {
    // The registry's gamma-mixture law: one component per group, weight = its share of the rays.
    double rays = 0.0;
    for (const auto& [k, g] : ws.groups) rays += g.rays;
    std::vector<transmittance::GammaComponent> components;
    for (const auto& [k, g] : ws.groups) {
      const double m = g.windows.mean();
      const double v = g.windows.var();
      components.push_back(
          {g.rays / rays, sigma * m, m > 0.0 ? transmittance::gamma_shape_rate(m, v).alpha : INFINITY});
    }
    const auto mixture = std::make_shared<const transmittance::GammaMixture>(std::move(components));
    add(
        "across-beam", "gamma law per transverse cell of side L, T the ray-weighted mean (gamma-mixture)",
        {{"window", L}, {"cell", L}, {"groups", static_cast<double>(ws.groups.size())}},
        [&](std::size_t, double t) { return mixture->log_transmittance(t); }, mixture);
  }
  // Local fields of blocks L³ (the statistics `weft fit --block` writes for rendering), clipped
  // to the active box so that each block holds exactly the beam's columns that cross it.
  {
    const BlockStats st = detail::block_stats(reader, reverse, w, progress);
    double blocks = 0.0;
    for (const auto& b : st.sums) blocks += b.n > 0.0 && b.s > 0.0 ? 1.0 : 0.0;
    const std::vector<std::tuple<std::string, std::string, Memory>> kinds{
        {"local-exponential", "blocks of side L, exponential per block (a coarse grid without statistics)",
         Memory::none},
        {"local-gamma",
         "blocks of side L with C and Var of column means, gamma hazard with memory from the ray's entry",
         Memory::from_entry},
        {"local-gamma-renewal", "blocks of side L, gamma hazard with memory restarting at every block",
         Memory::per_block},
    };
    for (const auto& [name, description, memory] : kinds) {
      auto curve = detail::block_field_curve(n, w, h, sigma, st, memory, depths);
      add(name, description, {{"block", L}, {"blocks", blocks}}, [&](std::size_t d, double) { return curve[d]; });
    }
    auto curve = detail::two_scale_curve(n, w, h, sigma, st, depths);
    add(kPredictedModel,
        "blocks of side L; per ray a persistent gamma factor (its memory from the entry, variance from the measured "
        "covariance of adjacent blocks) times an independent gamma factor per block (the prediction)",
        {{"block", L}, {"blocks", blocks}}, [&](std::size_t d, double) { return curve[d]; });
  }
  return out;
}

}  // namespace weft::fit
