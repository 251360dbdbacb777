// Predictive models of axis beams from window statistics and local fields (fit/models.h).
#include "weft/fit/models.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include <boost/math/special_functions/gamma.hpp>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/fit/fit.h"
#include "weft/fit/moments.h"
#include "weft/transmittance/gamma_mixture.h"
#include "weft/transmittance/gap_gamma.h"
#include "weft/transmittance/registry.h"
#include "weft/volume/beam.h"
#include "weft/volume/columns.h"

namespace weft::fit {
namespace {

constexpr std::size_t kShards = 64;  // fixed: results do not depend on the thread count
constexpr int kBins = 4096;          // histogram of window means for Eq. 16

/// Plain sums (Σ1, Σx, Σx²) of window means: exact to merge in any fixed order.
struct Sums {
  double n = 0.0;
  double s = 0.0;
  double s2 = 0.0;
  void add(double x) {
    n += 1.0;
    s += x;
    s2 += x * x;
  }
  void merge(const Sums& o) {
    n += o.n;
    s += o.s;
    s2 += o.s2;
  }
  [[nodiscard]] double mean() const { return n > 0.0 ? s / n : 0.0; }
  [[nodiscard]] double var() const {
    if (!(n > 0.0)) return 0.0;
    const double m = s / n;
    return std::max(0.0, s2 / n - m * m);
  }
};

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
  double max_mean = 0.0;
  std::map<GroupKey, Group> groups;
  std::vector<double> bin_count;
  std::vector<double> bin_sum;
};

double log_sum_exp_mean(const std::vector<double>& log_terms, const std::vector<double>& weights) {
  double hi = -std::numeric_limits<double>::infinity();
  double wsum = 0.0;
  for (std::size_t i = 0; i < log_terms.size(); ++i) {
    if (weights[i] > 0.0) hi = std::max(hi, log_terms[i]);
    wsum += weights[i];
  }
  if (!(wsum > 0.0) || !std::isfinite(hi)) return hi;
  double s = 0.0;
  for (std::size_t i = 0; i < log_terms.size(); ++i) {
    if (weights[i] > 0.0) s += weights[i] * std::exp(log_terms[i] - hi);
  }
  return hi + std::log(s / wsum);
}

/// One pass (twice: the histogram needs the largest window mean first) over every window of
/// w voxels of every column along the reader's axis; groups are transverse cells of `cell`
/// voxels anchored at the active box's lower corner (docs/validate.md "Blocks anchored to the
/// cloth"), so the same voxels at another index origin give the same groups.
WindowSummary summarize(const volume::ColumnReader& reader, int w, int cell, ProgressSink& progress) {
  const int n = static_cast<int>(reader.box().extent()[reader.axis()]);
  const std::int64_t u_lo = reader.box().min[static_cast<std::size_t>((reader.axis() + 1) % 3)];
  const std::int64_t v_lo = reader.box().min[static_cast<std::size_t>((reader.axis() + 2) % 3)];
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  const int positions = n - w + 1;
  std::vector<WindowSummary> parts(shards);
  for (int pass = 0; pass < 2; ++pass) {
    double top = 0.0;
    for (const auto& p : parts) top = std::max(top, p.max_mean);
    ProgressTask task(progress, fmt::format("window statistics {}", "xyz"[reader.axis()]), units);
    parallel_units(shards, [&](std::size_t shard) {
      volume::ColumnTile tile;
      std::vector<double> prefix(static_cast<std::size_t>(n) + 1);
      auto& part = parts[shard];
      if (pass == 1) {
        part.bin_count.assign(kBins, 0.0);
        part.bin_sum.assign(kBins, 0.0);
      }
      for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
        reader.read(unit, tile);
        for (int iu = 0; iu < tile.nu; ++iu) {
          for (int iv = 0; iv < tile.nv; ++iv) {
            const float* col = tile.column(iu, iv);
            prefix[0] = 0.0;
            for (int k = 0; k < n; ++k)
              prefix[static_cast<std::size_t>(k) + 1] = prefix[static_cast<std::size_t>(k)] + col[k];
            Group* g = nullptr;
            if (pass == 0) {
              const GroupKey key{(tile.u0 + iu - u_lo) / cell, (tile.v0 + iv - v_lo) / cell};
              g = &part.groups[key];
              g->rays += 1.0;
            }
            auto mean_at = [&](int s) {
              return (prefix[static_cast<std::size_t>(s + w)] - prefix[static_cast<std::size_t>(s)]) / w;
            };
            double column_sum = 0.0;
            for (int s = 0; s < positions; ++s) {
              const double m = mean_at(s);
              if (pass == 0) {
                part.all.add(m);
                column_sum += m;
                g->windows.add(m);
                part.max_mean = std::max(part.max_mean, m);
                if (m > 0.0)
                  part.nonzero.add(m);
                else
                  part.zeros += 1.0;
              } else if (m > 0.0) {
                const int b = std::min(kBins - 1, static_cast<int>(m / top * kBins));
                part.bin_count[static_cast<std::size_t>(b)] += 1.0;
                part.bin_sum[static_cast<std::size_t>(b)] += m;
              }
            }
            if (pass == 0 && positions > 0) {
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
  }
  WindowSummary out;
  out.bin_count.assign(kBins, 0.0);
  out.bin_sum.assign(kBins, 0.0);
  for (const auto& p : parts) {
    out.all.merge(p.all);
    out.moments.merge(p.moments);
    out.nonzero.merge(p.nonzero);
    out.zeros += p.zeros;
    out.max_mean = std::max(out.max_mean, p.max_mean);
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

/// Hazard integral of one block over [s0, s1) of memory (exact for the gamma hazard
/// Σ(s) = μ̄/(1 + κ s)): α [log1p(κ s1) − log1p(κ s0)], or μ̄ (s1 − s0) without variance.
double block_hazard(double sigma, double mean, double var, double s0, double s1) {
  if (!(mean > 0.0)) return 0.0;
  const double mu = sigma * mean;
  if (!(var > 0.0)) return mu * (s1 - s0);
  const double kappa = sigma * var / mean;
  const double alpha = mean * mean / var;
  return alpha * (std::log1p(kappa * s1) - std::log1p(kappa * s0));
}

enum class Memory { none, from_entry, per_block };

/// Block statistics of the beam's columns: blocks of B voxels anchored to the cloth, not to the
/// index lattice (docs/validate.md "Blocks anchored to the cloth"): across the beam at the active
/// box's lower corner, along it at the face where the beam enters (block 0 holds the first B
/// voxels every ray crosses, as the memory of the hazard starts there), clipped to the box, so
/// that a block holds exactly the columns (rays) of the beam that cross it and a translated copy
/// of the voxels gives the same blocks. Per block: the mean of C and the variance of the column
/// means over the block's length across its columns (Eq. 19 per block).
struct BlockStats {
  std::int64_t nu = 0, nv = 0, nb = 0;
  /// [(cu·nv + cv)·nb + cb], cb counted from the entry face: over the columns that hold some
  /// concentration along the beam (an open column, empty over the whole depth, adds only zeros)
  std::vector<Sums> sums;
  std::vector<double> rays;  ///< per coarse column (cu, cv): beam columns in it
  std::vector<double> open;  ///< per coarse column: its columns empty over the whole depth
  /// [(cu·nv + cv)·nb + cb]: Σ over the columns of (mean in block cb) × (mean in block cb + 1)
  std::vector<double> cross;
  [[nodiscard]] std::size_t index(std::int64_t u, std::int64_t v, std::int64_t b) const {
    return static_cast<std::size_t>((u * nv + v) * nb + b);
  }
  /// Over the columns that hold concentration.
  [[nodiscard]] const Sums& closed(std::int64_t u, std::int64_t v, std::int64_t b) const {
    return sums[index(u, v, b)];
  }
  /// Over every column of the block (open ones add n only: x + 0.0 is x, so the sums are those
  /// of all columns bit for bit).
  [[nodiscard]] Sums at(std::int64_t u, std::int64_t v, std::int64_t b) const {
    Sums all = sums[index(u, v, b)];
    all.n += open[static_cast<std::size_t>(u * nv + v)];
    return all;
  }
};

BlockStats block_stats(const volume::ColumnReader& reader, bool reverse, int B, ProgressSink& progress) {
  const int axis = reader.axis();
  const auto box = reader.box();
  const auto au = static_cast<std::size_t>((axis + 1) % 3);
  const auto av = static_cast<std::size_t>((axis + 2) % 3);
  const auto ext = box.extent();
  BlockStats st;
  st.nu = (ext[au] + B - 1) / B;
  st.nv = (ext[av] + B - 1) / B;
  st.nb = (ext[static_cast<std::size_t>(axis)] + B - 1) / B;
  const std::size_t cells = static_cast<std::size_t>(st.nu * st.nv * st.nb);
  if (cells > 50'000'000) fail("local fields: {} blocks of {} voxels is too many", cells, B);
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  std::vector<std::vector<Sums>> parts(shards, std::vector<Sums>(cells));
  std::vector<std::vector<double>> rays(shards, std::vector<double>(static_cast<std::size_t>(st.nu * st.nv), 0.0));
  std::vector<std::vector<double>> cross(shards, std::vector<double>(cells, 0.0));
  std::vector<std::vector<double>> open(shards, std::vector<double>(static_cast<std::size_t>(st.nu * st.nv), 0.0));
  ProgressTask task(progress, fmt::format("local fields {}", "xyz"[axis]), units);
  parallel_units(shards, [&](std::size_t shard) {
    volume::ColumnTile tile;
    for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
      reader.read(unit, tile);
      const int n = tile.depth;
      for (int iu = 0; iu < tile.nu; ++iu) {
        for (int iv = 0; iv < tile.nv; ++iv) {
          const std::int64_t cu = (tile.u0 + iu - box.min[au]) / B;
          const std::int64_t cv = (tile.v0 + iv - box.min[av]) / B;
          rays[shard][static_cast<std::size_t>(cu * st.nv + cv)] += 1.0;
          const float* col = tile.column(iu, iv);
          if (std::all_of(col, col + n, [](float x) { return x == 0.0f; })) {
            open[shard][static_cast<std::size_t>(cu * st.nv + cv)] += 1.0;
            continue;
          }
          Sums* block = &parts[shard][st.index(cu, cv, 0)];
          double* pair = &cross[shard][st.index(cu, cv, 0)];
          // Depth e from the entry face; block e / B.
          double prev = 0.0;
          for (int e0 = 0; e0 < n; e0 += B) {
            const int e1 = std::min(n, e0 + B);
            double sum = 0.0;
            for (int e = e0; e < e1; ++e) sum += static_cast<double>(col[reverse ? n - 1 - e : e]);
            const double m = sum / (e1 - e0);
            block[e0 / B].add(m);
            if (e0 > 0) pair[e0 / B - 1] += prev * m;
            prev = m;
          }
        }
      }
      task.step();
    }
  });
  st.sums.assign(cells, Sums{});
  st.rays.assign(static_cast<std::size_t>(st.nu * st.nv), 0.0);
  st.open.assign(st.rays.size(), 0.0);
  st.cross.assign(cells, 0.0);
  for (std::size_t sh = 0; sh < shards; ++sh) {
    for (std::size_t c = 0; c < cells; ++c) {
      st.sums[c].merge(parts[sh][c]);
      st.cross[c] += cross[sh][c];
    }
    for (std::size_t c = 0; c < st.rays.size(); ++c) {
      st.rays[c] += rays[sh][c];
      st.open[c] += open[sh][c];
    }
  }
  return st;
}

/// log T on `depths` of the beam through block fields: per coarse column the hazard of each
/// block integrated exactly, T the ray-weighted mean over coarse columns.
std::vector<double> block_field_curve(int n, int B, double h, double sigma, const BlockStats& st, Memory memory,
                                      const std::vector<double>& depths) {
  const std::size_t columns = static_cast<std::size_t>(st.nu * st.nv);
  std::vector<std::vector<double>> log_terms(depths.size(), std::vector<double>(columns, 0.0));
  parallel_units(columns, [&](std::size_t c) {
    const auto cu = static_cast<std::int64_t>(c) / st.nv;
    const auto cv = static_cast<std::int64_t>(c) % st.nv;
    // Walk the fine slices from the entry face; H at the start of slice k is `H`.
    double H = 0.0;
    std::size_t d = 0;
    double mean = 0.0;
    double var = 0.0;
    double origin = 0.0;  // where the current block's memory s = 0 lies (from_entry: the entry)
    for (int k = 0; k <= n && d < depths.size(); ++k) {
      const double s0 = k * h;
      if (k == n) {
        while (d < depths.size()) log_terms[d++][c] = -H;  // past the box: nothing more
        break;
      }
      if (k % B == 0) {
        const Sums b = st.at(cu, cv, k / B);
        if (memory == Memory::per_block) origin = s0;
        mean = b.mean();
        var = memory == Memory::none ? 0.0 : b.var();
      }
      const double inc = block_hazard(sigma, mean, var, s0 - origin, s0 + h - origin);
      while (d < depths.size() && depths[d] <= s0 + h) {
        const double t = std::max(depths[d], s0);
        log_terms[d++][c] = -(H + (t == s0 + h ? inc : block_hazard(sigma, mean, var, s0 - origin, t - origin)));
      }
      H += inc;
    }
  });
  std::vector<double> out(depths.size());
  for (std::size_t d = 0; d < depths.size(); ++d) out[d] = log_sum_exp_mean(log_terms[d], st.rays);
  return out;
}

/// The relative variance of the part of a ray's concentration that persists along the whole
/// coarse column: the mean over adjacent non-empty block pairs of Cov(m_b, m_b+1)/(C̄_b C̄_b+1),
/// the column means' covariance across a block boundary in units of the blocks' means; ≥ 0.
double persistent_relative_variance(const BlockStats& st, std::int64_t cu, std::int64_t cv) {
  double sum = 0.0;
  double pairs = 0.0;
  for (std::int64_t b = 0; b + 1 < st.nb; ++b) {
    const Sums& x = st.closed(cu, cv, b);
    const Sums& y = st.closed(cu, cv, b + 1);
    const double mx = x.mean();
    const double my = y.mean();
    if (!(mx > 0.0) || !(my > 0.0) || !(x.n > 0.0)) continue;
    sum += (st.cross[st.index(cu, cv, b)] / x.n - mx * my) / (mx * my);
    pairs += 1.0;
  }
  return pairs > 0.0 ? std::max(0.0, sum / pairs) : 0.0;
}

/// The prediction (docs/validate.md "The prediction"): a ray's concentration in block b is
/// C̄_b · P · Q_b, P ~ Gamma(mean 1, relative variance v_p) one per ray for its whole path (the
/// part that persists from block to block: which yarn or gap the ray runs in), Q_b ~ Gamma(mean
/// 1, v_b) one per ray and block (the part that does not), with (1 + v_p)(1 + v_b) = 1 + the
/// block's relative variance of column means. Given P, blocks are independent gamma laws
/// (the renewal); over P the memory runs from the entry. T(t) = E_P Π_b (1 + σC̄_b P s_b v_b)^(−1/v_b)
/// per coarse column, E_P by kNodes equal-probability quantiles of P.
std::vector<double> two_scale_curve(int n, int B, double h, double sigma, const BlockStats& st,
                                    const std::vector<double>& depths) {
  constexpr int kNodes = 32;
  const std::size_t columns = static_cast<std::size_t>(st.nu * st.nv);
  std::vector<std::vector<double>> log_terms(depths.size(), std::vector<double>(columns, 0.0));
  parallel_units(columns, [&](std::size_t c) {
    const auto cu = static_cast<std::int64_t>(c) / st.nv;
    const auto cv = static_cast<std::int64_t>(c) % st.nv;
    const double vp = persistent_relative_variance(st, cu, cv);
    std::vector<double> p{1.0};
    if (vp > 0.0) {
      p.resize(kNodes);
      const double shape = 1.0 / vp;
      for (int j = 0; j < kNodes; ++j)
        p[static_cast<std::size_t>(j)] = boost::math::gamma_p_inv(shape, (j + 0.5) / kNodes) / shape;
    }
    const std::vector<double> ones(p.size(), 1.0);
    std::vector<double> H(p.size(), 0.0);
    std::vector<double> at(p.size(), 0.0);
    std::vector<double> inc(p.size(), 0.0);
    std::size_t d = 0;
    double mean = 0.0;
    double vb = 0.0;
    double entry = 0.0;
    // Hazard of node j over [a, b) of the current block (memory of Q_b from the block's entry).
    auto hazard = [&](std::size_t j, double a, double b) {
      const double mu = sigma * mean * p[j];
      if (!(vb > 0.0)) return mu * (b - a);
      return (std::log1p(mu * vb * (b - entry)) - std::log1p(mu * vb * (a - entry))) / vb;
    };
    // Open columns (no concentration along the whole beam) transmit everything, exactly.
    const double f_open = st.rays[c] > 0.0 ? st.open[c] / st.rays[c] : 0.0;
    auto with_open = [&](double log_closed) {
      if (!(f_open > 0.0)) return log_closed;
      return std::log(f_open + (1.0 - f_open) * std::exp(log_closed));
    };
    for (int k = 0; k <= n && d < depths.size(); ++k) {
      const double s0 = k * h;
      if (k == n) {
        for (std::size_t j = 0; j < p.size(); ++j) at[j] = -H[j];
        const double past = with_open(log_sum_exp_mean(at, ones));  // past the box: nothing more
        while (d < depths.size()) log_terms[d++][c] = past;
        break;
      }
      if (k % B == 0) {
        const Sums& b = st.closed(cu, cv, k / B);
        mean = b.mean();
        const double rel = mean > 0.0 ? b.var() / (mean * mean) : 0.0;
        vb = std::max(0.0, (1.0 + rel) / (1.0 + vp) - 1.0);
        entry = s0;
      }
      // The slice's hazard once per node (the beam's depths are the slice ends, k·h).
      for (std::size_t j = 0; j < p.size(); ++j) inc[j] = hazard(j, s0, s0 + h);
      while (d < depths.size() && depths[d] <= s0 + h) {
        const double t = std::max(depths[d], s0);
        for (std::size_t j = 0; j < p.size(); ++j) at[j] = -(H[j] + (t == s0 + h ? inc[j] : hazard(j, s0, t)));
        log_terms[d++][c] = with_open(log_sum_exp_mean(at, ones));
      }
      for (std::size_t j = 0; j < p.size(); ++j) H[j] += inc[j];
    }
  });
  std::vector<double> out(depths.size());
  for (std::size_t d = 0; d < depths.size(); ++d) out[d] = log_sum_exp_mean(log_terms[d], st.rays);
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
    spec.params = {{"mean_extinction", sigma * mean}, {"alpha", mean * mean / var}};
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
  const double beta = mean / var;
  const double alpha = mean * beta;
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
  const int w = spec.scale > 0.0 ? static_cast<int>(std::clamp<double>(std::round(spec.scale / h), 1.0, n)) : n;
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
         {"alpha", var > 0.0 ? mean * mean / var : INFINITY},
         {"beta", var > 0.0 ? mean / var : INFINITY}},
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
                                     f0, sigma * mean, var > 0.0 ? mean * mean / var : INFINITY))
                               : std::unique_ptr<transmittance::Law>(std::make_unique<transmittance::GammaMixture>(
                                     std::vector<transmittance::GammaComponent>{{1.0, 0.0, INFINITY}}));
    add(
        "gap-gamma", "gap fraction f0 (empty windows of length L) plus a gamma law of the others",
        {{"window", L},
         {"gap_fraction", f0},
         {"mean_concentration", mean},
         {"var_concentration", var},
         {"alpha", var > 0.0 ? mean * mean / var : INFINITY},
         {"beta", var > 0.0 ? mean / var : INFINITY}},
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
      components.push_back({g.rays / rays, sigma * m, v > 0.0 && m > 0.0 ? m * m / v : INFINITY});
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
    const BlockStats st = block_stats(reader, reverse, w, progress);
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
      auto curve = block_field_curve(n, w, h, sigma, st, memory, depths);
      add(name, description, {{"block", L}, {"blocks", blocks}}, [&](std::size_t d, double) { return curve[d]; });
    }
    auto curve = two_scale_curve(n, w, h, sigma, st, depths);
    add(kPredictedModel,
        "blocks of side L; per ray a persistent gamma factor (its memory from the entry, variance from the measured "
        "covariance of adjacent blocks) times an independent gamma factor per block (the prediction)",
        {{"block", L}, {"blocks", blocks}}, [&](std::size_t d, double) { return curve[d]; });
  }
  return out;
}

}  // namespace weft::fit
