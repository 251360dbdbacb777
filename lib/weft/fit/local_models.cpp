// The local models of fit/models.h: block statistics anchored to the cloth and the beam through
// them (fit/local_models.h).
#include "weft/fit/local_models.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/fit/gamma_nodes.h"
#include "weft/fit/node_kernels.h"
#include "weft/transmittance/gamma_hazard.h"

namespace weft::fit::detail {
namespace {

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

/// log T per depth: the ray-weighted mean of the coarse columns' T, depth by depth in parallel
/// (each depth's sum in column order: the same bits for any thread count).
std::vector<double> mean_over_columns(const std::vector<std::vector<double>>& log_terms,
                                      const std::vector<double>& rays) {
  std::vector<double> out(log_terms.size());
  parallel_units(log_terms.size(), [&](std::size_t d) { out[d] = log_sum_exp_mean(log_terms[d], rays); });
  return out;
}

}  // namespace

/// log T on `depths` of the beam through block fields: per coarse column the hazard of each
/// block integrated exactly, T the ray-weighted mean over coarse columns.
std::vector<double> block_field_curve(int n, int B, double h, double sigma, const BlockStats& st, Memory memory,
                                      const std::vector<double>& depths) {
  const std::size_t columns = static_cast<std::size_t>(st.nu * st.nv);
  std::vector<std::vector<double>> log_terms(depths.size(), std::vector<double>(columns, 0.0));
  parallel_units(columns, [&](std::size_t c) {
    const auto cu = static_cast<std::int64_t>(c) / st.nv;
    const auto cv = static_cast<std::int64_t>(c) % st.nv;
    // Walk the fine slices from the entry face, the block hazard (transmittance::GammaHazard,
    // the render medium's) entered at each block face; a block without variance is exponential.
    transmittance::GammaHazard hazard(
        memory == Memory::per_block ? transmittance::MemoryRule::renewal : transmittance::MemoryRule::segment,
        transmittance::Origin::source);
    std::size_t d = 0;
    int block = -1;  // the block of slice k: k / B, counted (no division per slice)
    for (int k = 0; k <= n && d < depths.size(); ++k) {
      const double s0 = k * h;
      if (k == n) {
        while (d < depths.size()) log_terms[d++][c] = -hazard.hazard();  // past the box: nothing more
        break;
      }
      if (k == (block + 1) * B) {
        ++block;
        // Blocks are anchored at the entry face (docs/validate.md "Blocks anchored to the cloth").
        const Sums b = st.at(cu, cv, block);
        hazard.enter(sigma, b.mean(), memory == Memory::none ? 0.0 : b.var(), s0);
      }
      // The slice's hazard once: at its end (where the beam's depths lie) H after advance() is
      // H before plus the same piece, bit for bit; a depth inside the slice looks ahead.
      const double before = hazard.hazard();
      hazard.advance(s0, s0 + h);
      while (d < depths.size() && depths[d] <= s0 + h) {
        const double t = std::max(depths[d], s0);
        log_terms[d++][c] = t == s0 + h ? -hazard.hazard() : -(before + hazard.piece(s0, t));
      }
    }
  });
  return mean_over_columns(log_terms, st.rays);
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
  const std::size_t columns = static_cast<std::size_t>(st.nu * st.nv);
  std::vector<std::vector<double>> log_terms(depths.size(), std::vector<double>(columns, 0.0));
  // Every column's v_p first: the nodes' table is built once for all their shapes 1/v_p.
  std::vector<double> persistent(columns, 0.0);
  std::vector<double> shapes;
  for (std::size_t c = 0; c < columns; ++c) {
    persistent[c] =
        persistent_relative_variance(st, static_cast<std::int64_t>(c) / st.nv, static_cast<std::int64_t>(c) % st.nv);
    if (persistent[c] > 0.0) shapes.push_back(1.0 / persistent[c]);
  }
  const GammaNodes table(shapes);
  parallel_units(columns, [&](std::size_t c) {
    const auto cu = static_cast<std::int64_t>(c) / st.nv;
    const auto cv = static_cast<std::int64_t>(c) % st.nv;
    const double vp = persistent[c];
    std::vector<double> p{1.0};
    if (vp > 0.0) {
      p.resize(kNodes);
      table.nodes(1.0 / vp, p.data());
    }
    // Nodes are in increasing P, so every slice adds at least as much hazard to node j + 1 as to
    // node j: once node j is kNegligibleHazard above node 0 it stays there, and it and every
    // later node are dropped for the rest of the column (`live`), which changes no bit of T.
    std::size_t live = p.size();
    std::vector<double> H(p.size(), 0.0);
    std::vector<double> at(p.size(), 0.0);
    std::vector<double> inc(p.size(), 0.0);
    std::size_t d = 0;
    double mean = 0.0;
    double vb = 0.0;
    double entry = 0.0;
    double last = 0.0;  // log T at the last slice end evaluated, if no hazard was added since
    bool have_last = false;
    std::vector<double> scratch(p.size(), 0.0);
    // Hazards of the live nodes over [a, b) of the current block, a and b in the block's
    // profile-weighted distance from its entry (below): the gamma hazard of Q_b (α = 1/v_b,
    // κ = μ v_b) with memory from the block's entry (transmittance::GammaCell's integral, node by
    // node in node_hazards).
    auto hazards = [&](double a, double b, double* out) {
      node_hazards(p.data(), live, sigma * mean, vb, a, b - a, out);
    };
    // The depth profile inside the block (BlockStats::slices): the factor Q_b multiplies the
    // whole block, so the optical depth to s inside it is σ P Q_b ∫ m(x) dx, the block's mean
    // times the distance u(s) = L_b ∫₀ˢ m / ∫₀^{L_b} m — the hazard of the uniform block taken
    // at u instead of s. u = s without a profile; at the block's end u = L_b exactly (cum/total
    // = 1), so every block-end value is the uniform block's (docs/validate.md "The prediction").
    const double* profile = st.depth > 0 ? &st.slices[c * static_cast<std::size_t>(st.depth)] : nullptr;
    double block_total = 0.0;  // Σ of the profile over the current block
    double block_length = 0.0;
    double cum = 0.0;  // Σ of the profile over the block's slices before k
    auto warped = [&](double cumulative, double distance) {
      return profile != nullptr && block_total > 0.0 ? block_length * (cumulative / block_total) : distance;
    };
    // Open columns (no concentration along the whole beam) transmit everything, exactly.
    const double f_open = st.rays[c] > 0.0 ? st.open[c] / st.rays[c] : 0.0;
    auto with_open = [&](double log_closed) {
      if (!(f_open > 0.0)) return log_closed;
      return std::log(f_open + (1.0 - f_open) * std::exp(log_closed));
    };
    int block = -1;
    for (int k = 0; k <= n && d < depths.size(); ++k) {
      const double s0 = k * h;
      if (k == n) {
        for (std::size_t j = 0; j < live; ++j) at[j] = -H[j];
        const double past =
            with_open(log_mean_exp_nodes(at.data(), live, p.size(), scratch.data()));  // past the box: nothing more
        while (d < depths.size()) log_terms[d++][c] = past;
        break;
      }
      if (k == (block + 1) * B) {  // k % B == 0, counted as above
        ++block;
        const Sums& b = st.closed(cu, cv, block);
        mean = b.mean();
        const double rel = mean > 0.0 ? b.var() / (mean * mean) : 0.0;
        vb = std::max(0.0, (1.0 + rel) / (1.0 + vp) - 1.0);
        entry = s0;
        const int end = std::min(n, k + B);
        block_length = (end - k) * h;
        block_total = 0.0;
        if (profile != nullptr) {
          for (int j = k; j < end; ++j) block_total += profile[j];
        }
        cum = 0.0;
      }
      // The slice [s0, s0 + h) in the block's warped distance: [u0, u1).
      const double u0 = warped(cum, s0 - entry);
      const double cum1 = cum + (profile != nullptr ? profile[k] : 0.0);
      const double u1 = warped(cum1, s0 + h - entry);
      cum = cum1;
      // A block without concentration adds exactly 0 to every node's hazard: at the slice's end
      // T is the value at the previous slice's end (H there was H + inc, the same additions).
      const bool still = !(mean > 0.0);
      // The slice's hazard once per node (the beam's depths are the slice ends, k·h).
      if (!still) hazards(u0, u1, inc.data());
      bool ended = false;
      while (d < depths.size() && depths[d] <= s0 + h) {
        const double t = std::max(depths[d], s0);
        if (t == s0 + h) {
          if (!(still && have_last)) {
            for (std::size_t j = 0; j < live; ++j) at[j] = -(H[j] + (still ? 0.0 : inc[j]));
            last = with_open(log_mean_exp_nodes(at.data(), live, p.size(), scratch.data()));
          }
          ended = true;
          log_terms[d++][c] = last;
          continue;
        }
        if (!still) hazards(u0, u0 + (t - s0) / h * (u1 - u0), scratch.data());
        for (std::size_t j = 0; j < live; ++j) at[j] = -(H[j] + (still ? 0.0 : scratch[j]));
        log_terms[d++][c] = with_open(log_mean_exp_nodes(at.data(), live, p.size(), scratch.data()));
      }
      have_last = ended;
      if (still) continue;
      for (std::size_t j = 0; j < live; ++j) H[j] += inc[j];
      while (live > 1 && H[live - 1] - H[0] > kNegligibleHazard) --live;
    }
  });
  return mean_over_columns(log_terms, st.rays);
}

}  // namespace weft::fit::detail
