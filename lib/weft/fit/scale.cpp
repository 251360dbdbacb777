// The scale of the local statistics: autocorrelation of C, fibre- and yarn-scale lengths.
#include "weft/fit/scale.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>

#include "weft/core/error.h"
#include "weft/core/number_name.h"
#include "weft/core/parallel.h"
#include "weft/core/parse_number.h"
#include "weft/fit/window_stats.h"
#include "weft/volume/columns.h"

namespace weft::fit {
namespace {
// `value` of the window option as `asker` writes it: `--window yarn-measured`, `window="yarn-measured"`.
std::string window_value(const Spelling& option, FrontEnd asker, std::string_view value) {
  return asker == FrontEnd::cli ? fmt::format("{}{}", option.cli, value)
                                : fmt::format("{}\"{}\"", option.python, value);
}

// A window given as a length: a positive finite number. A number that is not one (nan, inf, past
// double's range) is said as such, not as an unknown name.
double window_length(const std::string& text, const std::string& option) {
  const std::optional<double> v = parse_option_number(text);
  if (!v) {
    const std::string problem = number_problem(text);
    if (problem == kNotANumber) fail("{} '{}' is not yarn, yarn-measured, corr, extent or a length", option, text);
    fail("{} '{}' is {}", option, text, problem);
  }
  if (!std::isfinite(*v) || !(*v > 0.0)) fail("{} must be finite and > 0, got {}", option, text);
  return *v;
}

constexpr std::size_t kShards = 64;  // fixed: results do not depend on the thread count

/// Autocovariance of C along the reader's axis at lags [l0, l1) about `mean`, per pair of
/// voxels at that lag; one streaming pass, summed per shard, merged in shard order.
std::vector<double> covariance(const volume::ColumnReader& reader, double mean, std::size_t l0, std::size_t l1,
                               ProgressSink& progress) {
  const int axis = reader.axis();
  const int n = static_cast<int>(reader.box().extent()[axis]);
  const std::size_t units = reader.tile_count();
  const std::size_t shards = std::min(kShards, units);
  std::vector<std::vector<double>> parts(shards, std::vector<double>(l1 - l0, 0.0));
  ProgressTask task(progress, fmt::format("autocorrelation {}", "xyz"[axis]), units);
  parallel_units(shards, [&](std::size_t shard) {
    volume::ColumnTile tile;
    std::vector<double> dev(static_cast<std::size_t>(n));
    auto& acc = parts[shard];
    for (std::size_t unit = shard * units / shards; unit < (shard + 1) * units / shards; ++unit) {
      reader.read(unit, tile);
      for (int iu = 0; iu < tile.nu; ++iu) {
        for (int iv = 0; iv < tile.nv; ++iv) {
          const float* col = tile.column(iu, iv);
          for (int k = 0; k < n; ++k) dev[static_cast<std::size_t>(k)] = static_cast<double>(col[k]) - mean;
          for (std::size_t l = l0; l < l1; ++l) {
            double s = 0.0;
            for (std::size_t k = 0; k + l < static_cast<std::size_t>(n); ++k) s += dev[k] * dev[k + l];
            acc[l - l0] += s;
          }
        }
      }
      task.step();
    }
  });
  std::vector<double> cov(l1 - l0, 0.0);
  for (const auto& p : parts) {
    for (std::size_t l = l0; l < l1; ++l) cov[l - l0] += p[l - l0];
  }
  for (std::size_t l = l0; l < l1; ++l) cov[l - l0] /= static_cast<double>(n - static_cast<int>(l));
  return cov;
}

double box_mean(const volume::Grid& grid) {
  const auto ext = grid.active_bbox().extent();
  return grid.sum() / (static_cast<double>(ext[0]) * static_cast<double>(ext[1]) * static_cast<double>(ext[2]));
}

/// R smoothed by a triangle of half-width w lags (R even in l): the autocorrelation of C
/// box-averaged over w voxels along the axis, normalised to 1 at lag 0.
std::vector<double> smoothed(const std::vector<double>& r, int w) {
  const int n = static_cast<int>(r.size());
  auto at = [&](int l) { return r[static_cast<std::size_t>(std::min(std::abs(l), n - 1))]; };
  std::vector<double> out(r.size(), 0.0);
  for (int l = 0; l < n; ++l) {
    double s = 0.0;
    double wsum = 0.0;
    for (int m = -w; m <= w; ++m) {
      const double weight = 1.0 - static_cast<double>(std::abs(m)) / (w + 1);
      s += weight * at(l + m);
      wsum += weight;
    }
    out[static_cast<std::size_t>(l)] = s / wsum;
  }
  const double r0 = out[0];
  if (r0 > 0.0) {
    for (auto& x : out) x /= r0;
  }
  return out;
}

}  // namespace

std::optional<double> lag_falling_to_inverse_e(const std::vector<double>& r) {
  const double threshold = std::exp(-1.0);
  if (r.empty()) return std::nullopt;
  if (r[0] <= threshold) return 0.0;  // no correlation at all (a uniform grid's R is all zeros)
  for (std::size_t l = 1; l < r.size(); ++l) {
    if (r[l] <= threshold) {
      const double prev = r[l - 1];  // > threshold >= r[l]: the interpolation never divides by 0
      return static_cast<double>(l) - 1.0 + (prev - threshold) / (prev - r[l]);
    }
  }
  return std::nullopt;
}

double lag_at_inverse_e(const std::vector<double>& r) {
  return lag_falling_to_inverse_e(r).value_or(r.empty() ? 0.0 : static_cast<double>(r.size() - 1));
}

std::vector<double> autocorrelation(const volume::Grid& grid, int axis, int max_lag, ProgressSink& progress) {
  if (axis < 0 || axis > 2) fail("autocorrelation: axis must be 0, 1 or 2, got {}", axis);
  if (grid.active_voxel_count() == 0) fail("autocorrelation: grid '{}' has no active voxels", grid.name());
  const volume::ColumnReader reader(grid, axis);
  const int n = static_cast<int>(reader.box().extent()[axis]);
  max_lag = std::clamp(max_lag, 0, n - 1);
  auto cov = covariance(reader, box_mean(grid), 0, static_cast<std::size_t>(max_lag) + 1, progress);
  const double c0 = cov[0];
  for (auto& c : cov) c = c0 > 0.0 ? c / c0 : 0.0;
  return cov;
}

double correlation_length(const volume::Grid& grid, int axis, ProgressSink& progress) {
  if (axis < 0 || axis > 2) fail("correlation length: axis must be 0, 1 or 2, got {}", axis);
  if (grid.active_voxel_count() == 0) fail("correlation length: grid '{}' has no active voxels", grid.name());
  const volume::ColumnReader reader(grid, axis);
  const int n = static_cast<int>(reader.box().extent()[axis]);
  const double h = grid.voxel_size();
  const int max_lag = std::min(n - 1, 128);
  if (max_lag < 1) return n * h;
  const double mean = box_mean(grid);
  // Lags in growing blocks (up to 8, 32, 128): most media decorrelate within the first.
  std::vector<double> cov;
  const double threshold = std::exp(-1.0);
  double prev = 1.0;
  std::size_t next = 0;
  for (std::size_t end : {std::size_t{9}, std::size_t{33}, static_cast<std::size_t>(max_lag) + 1}) {
    end = std::min(end, static_cast<std::size_t>(max_lag) + 1);
    if (end <= next) continue;
    const auto block = covariance(reader, mean, next, end, progress);
    cov.insert(cov.end(), block.begin(), block.end());
    if (!(cov[0] > 0.0)) return n * h;
    for (std::size_t l = std::max<std::size_t>(next, 1); l < end; ++l) {
      const double r = cov[l] / cov[0];
      if (r <= threshold) return (static_cast<double>(l) - 1.0 + (prev - threshold) / (prev - r)) * h;
      prev = r;
    }
    next = end;
  }
  return n * h;
}

double measured_yarn_scale(const volume::Grid& grid, ProgressSink& progress, FrontEnd asker, const Spelling& option) {
  if (grid.active_voxel_count() == 0) fail("yarn scale: grid '{}' has no active voxels", grid.name());
  const double h = grid.voxel_size();
  const auto unmeasurable = [&](const std::string& why) {
    fail("yarn scale: cannot be measured on grid '{}': {}: pass {} (about the yarn diameter, in the grid's units)",
         grid.name(), why, option.in(asker) + "LENGTH");
  };
  // Per axis 3 ℓ_y, or a lower bound (3 × the largest lag) where the smoothed R stays above 1/e.
  // An axis one voxel long has no lag and says nothing.
  struct Axis {
    double scale = 0.0;
    bool lower_bound = false;
    char name = 'x';
  };
  std::vector<Axis> axes;
  for (int axis = 0; axis < 3; ++axis) {
    const int n = static_cast<int>(grid.active_bbox().extent()[static_cast<std::size_t>(axis)]);
    if (n < 2) continue;
    // Lags up to half the extent (at most 256): the yarn-scale part must fit in the box.
    const int max_lag = std::clamp(n / 2, 1, 256);
    const auto r = autocorrelation(grid, axis, max_lag, progress);
    // R(0) is the box variance, the same along every axis: 0 only when C is uniform.
    if (!(r[0] > 0.0)) unmeasurable("its concentration is uniform over the active box (no structure to correlate)");
    const double fibre = lag_at_inverse_e(r);
    const int w = std::max(1, static_cast<int>(std::lround(fibre)));
    const std::optional<double> yarn = lag_falling_to_inverse_e(smoothed(r, w));
    axes.push_back({3.0 * yarn.value_or(static_cast<double>(max_lag)) * h, !yarn, "xyz"[axis]});
  }
  if (axes.empty()) unmeasurable("its active box is one voxel (no structure to correlate)");
  // The median over the axes (the lower of two when the box is one voxel thick along the third).
  std::sort(axes.begin(), axes.end(), [](const Axis& a, const Axis& b) { return a.scale < b.scale; });
  const Axis& median = axes[(axes.size() - 1) / 2];
  if (median.lower_bound) {
    std::string names;
    for (const Axis& a : axes) {
      if (a.lower_bound) names += fmt::format("{}{}", names.empty() ? "" : ", ", a.name);
    }
    unmeasurable(fmt::format(
        "the autocorrelation of C never falls to 1/e within half the box along {} (the structure is larger than the "
        "grid)",
        names));
  }
  return median.scale;
}

void check_scale_text(const std::string& text, const std::string& option) {
  if (text == "yarn" || text == "yarn-measured" || text == "corr" || text == "extent") return;
  (void)window_length(text, option);
}

StatisticsScale resolve_scale(const std::string& text, const volume::Grid& grid, const volume::Provenance& provenance,
                              ProgressSink& progress, FrontEnd asker, const Spelling& option) {
  StatisticsScale s;
  if (text == "yarn") {
    // No silent voxel-dependent default: the measured scale drifts with the voxel size
    // (docs/validate.md), so a grid without a recorded yarn diameter must say its scale.
    if (!provenance.yarn_diameter) {
      fail(
          "grid '{}' records no yarn diameter (not written by weft gen): pass {} (about the yarn diameter, in the "
          "grid's units) or {} (estimated from the voxels; it depends on the voxel size)",
          grid.name(), option.in(asker) + "LENGTH", window_value(option, asker, "yarn-measured"));
    }
    s.rule = "yarn";
    s.length.fill(*provenance.yarn_diameter);
    s.source = "yarn diameter from the grid's provenance";
    return s;
  }
  if (text == "yarn-measured") {
    s.rule = "yarn-measured";
    s.length.fill(measured_yarn_scale(grid, progress, asker, option));
    s.source = "yarn scale measured from the voxels (depends on the voxel size: docs/validate.md)";
    return s;
  }
  if (text == "corr") {
    s.rule = "corr";
    for (int a = 0; a < 3; ++a) s.length[static_cast<std::size_t>(a)] = correlation_length(grid, a, progress);
    s.source = "fibre-scale correlation length along each axis (1/e lag; depends on the voxel size)";
    return s;
  }
  if (text == "extent") {
    s.rule = "extent";
    s.length.fill(0.0);
    s.source = "the grid's extent along each beam";
    return s;
  }
  s.rule = "length";
  s.length.fill(window_length(text, "window"));
  s.source = "given length";
  return s;
}

ScaleUse scale_use(const StatisticsScale& scale, const volume::Grid& grid, bool local_models, FrontEnd asker,
                   const Spelling& option) {
  if (grid.active_voxel_count() == 0) fail("window: grid '{}' has no active voxels", grid.name());
  const double h = grid.voxel_size();
  const auto extent = grid.active_bbox().extent();
  // Clamped axes grouped by (what happened, length given): one line for the usual equal lengths.
  struct Clamp {
    bool shorter = false;
    double given = 0.0;
    std::string axes;
  };
  std::vector<Clamp> clamps;
  std::string one_voxel;
  ScaleUse use;
  for (std::size_t a = 0; a < 3; ++a) {
    const int n = static_cast<int>(extent[a]);
    const double given = scale.length[a];
    const int w = window_voxels(given, h, n);
    use.length[a] = w * h;
    const char axis = "xyz"[a];
    if (w == 1) one_voxel += fmt::format("{}{}", one_voxel.empty() ? "" : ", ", axis);
    if (!(given > 0.0)) continue;  // the extent, by definition
    const double voxels = std::round(given / h);
    if (voxels >= 1.0 && voxels <= n) continue;
    const bool shorter = voxels < 1.0;
    const auto same = std::find_if(clamps.begin(), clamps.end(),
                                   [&](const Clamp& c) { return c.shorter == shorter && c.given == given; });
    if (same != clamps.end()) {
      same->axes += fmt::format(", {}", axis);
    } else {
      clamps.push_back({shorter, given, std::string(1, axis)});
    }
  }
  // The length is echoed as given (number_name: 1e-320, not {:g}'s 9.99989e-321).
  for (const Clamp& c : clamps) {
    use.notes.push_back(c.shorter ? fmt::format("{}{} is shorter than half a voxel ({:g}) along {}: one voxel is used",
                                                option.in(asker), number_name(c.given), 0.5 * h, c.axes)
                                  : fmt::format("{}{} is longer than the active box along {}: the box's extent is used",
                                                option.in(asker), number_name(c.given), c.axes));
  }
  if (local_models && !one_voxel.empty())
    use.notes.push_back(fmt::format(
        "the window is one voxel along {}: the local models' blocks then hold each voxel's own value and reproduce "
        "the ground truth instead of predicting it",
        one_voxel));
  return use;
}

}  // namespace weft::fit
