// The render-study matrix's judgement and reports (render_matrix_report.h; docs/render.md §6e).
#include "weft/study/render_matrix_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "weft/render/cloth_scene.h"

namespace weft::study {
namespace {

using nlohmann::json;

const StudyCandidate& fine_of(const MatrixCaseResult& r) {
  for (const auto& c : r.candidates)
    if (c.study.factor == 1) return c.study;
  return r.candidates.front().study;
}

const MatrixCandidate* fine_entry(const MatrixCaseResult& r) {
  for (const auto& c : r.candidates)
    if (c.study.factor == 1) return &c;
  return nullptr;
}

double relative(double v, double mean) { return mean > 0.0 ? v / mean : 0.0; }

double bias_z(const StudyCandidate& c) {
  return c.cloth_bias_sq_stderr > 0.0 ? c.cloth_bias_sq / c.cloth_bias_sq_stderr : 0.0;
}

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string coarser(int factor) { return factor == 0 ? std::string("slab") : fmt::format("{}x", factor); }

/// Where a verdict reaches the speed-up goal: ", 3x from RMSE 7.2%" or ", never 3x".
std::string goal_error_text(double error) {
  return std::isfinite(error) ? fmt::format(", {:g}x from RMSE {:.1f}%", kMatrixSpeedupGoal, 100.0 * error)
                              : fmt::format(", never {:g}x", kMatrixSpeedupGoal);
}

std::string percent(double v, double mean) { return fmt::format("{:.1f}", 100.0 * relative(v, mean)); }

/// Worst cloth bias per representation at each block size, and the level (docs/render.md §6e).
std::string scales_markdown(const std::vector<MatrixHeadline>& headlines) {
  std::string md =
      "\nBias against image scale: worst cloth bias over the set-ups after box-filtering k x k pixels, and the "
      "level (mean difference over the cloth, largest magnitude), % of the mean cloth pixel:\n\n| cloth | "
      "representation |";
  std::string rule = "|---|---|";
  for (const int k : kBiasBlocks) {
    md += fmt::format(" {} px |", k);
    rule += "---|";
  }
  md += " level |\n" + rule + "---|\n";
  for (const auto& h : headlines) {
    std::vector<const MatrixVerdict*> rows;
    for (const auto& v : h.verdicts) rows.push_back(&v);
    for (const auto& v : h.floors) rows.push_back(&v);
    for (const MatrixVerdict* row : rows) {
      const MatrixVerdict& v = *row;
      md += fmt::format("| {} | {} |", h.cloth, v.name);
      for (const double b : v.worst_relative_bias_by_block)
        md += b < 0.0 ? std::string(" – |") : fmt::format(" {:.1f} |", 100.0 * b);
      md += fmt::format(" {:+.1f} |\n", 100.0 * v.worst_relative_level);
    }
  }
  return md;
}

/// One case's cloth bias and its scales into a verdict: the worst and the sum (for the mean) of
/// the relative bias, the worst at each block size, the level of largest magnitude.
void take_case(MatrixVerdict& v, const MatrixCaseResult& r, double cloth_bias, const ScaleBias& scales) {
  const double rb = relative(cloth_bias, r.cloth_mean);
  if (rb > v.worst_relative_bias) {
    v.worst_relative_bias = rb;
    v.worst_case = r.c.name;
  }
  v.mean_relative_bias += rb;
  // −1: too few blocks of that size lie wholly on the cloth in every judged case (a small film).
  v.worst_relative_bias_by_block.resize(scales.blocks.size(), -1.0);
  for (std::size_t i = 0; i < scales.blocks.size(); ++i)
    if (scales.blocks[i].blocks >= kMinBiasBlocks)
      v.worst_relative_bias_by_block[i] =
          std::max(v.worst_relative_bias_by_block[i], relative(scales.blocks[i].bias(), r.cloth_mean));
  const double level = relative(scales.level.difference, r.cloth_mean);
  if (std::abs(level) > std::abs(v.worst_relative_level)) v.worst_relative_level = level;
}

/// Each factor's resolution floor over one cloth's set-ups, as a verdict (worst and mean
/// relative bias at 1 px and at every block size, the level of largest magnitude).
std::vector<MatrixVerdict> floor_verdicts(const MatrixSpec& spec, const std::vector<MatrixCaseResult>& results,
                                          const std::string& cloth) {
  std::vector<MatrixVerdict> out;
  for (const int f : spec.study.factors) {
    MatrixVerdict v;
    v.name = fmt::format("resolution-floor-{}x", f);
    v.model = "resolution floor";
    v.factor = f;
    v.worst_relative_bias = -1.0;
    int n = 0;
    for (const auto& r : results) {
      if (r.c.pattern != cloth) continue;
      for (const ResolutionFloor& rf : r.resolution_floors) {
        if (rf.factor != f || rf.scales.blocks.empty()) continue;
        take_case(v, r, rf.scales.blocks.front().bias(), rf.scales);
        ++n;
      }
    }
    if (n == 0) continue;
    v.mean_relative_bias /= n;
    out.push_back(std::move(v));
  }
  return out;
}

/// Per case, each split candidate's bias (level) over the cloth: full, and its transmission,
/// single and multiple scattering (render_components.h), % of the mean cloth pixel.
std::string components_markdown(const std::vector<MatrixCaseResult>& results) {
  std::string rows;
  for (const auto& r : results) {
    for (const auto& mc : r.candidates) {
      const StudyCandidate& c = mc.study;
      if (c.components.empty()) continue;
      rows += fmt::format("| {} | {} | {} z {:.1f} ({:+.1f}) |", r.c.name, c.name, percent(c.cloth_bias, r.cloth_mean),
                          bias_z(c), 100.0 * relative(c.cloth_scales.level.difference, r.cloth_mean));
      for (const ComponentBias& k : c.components)
        rows += fmt::format(" {} z {:.1f} ({:+.1f} ± {:.1f}) |", percent(k.bias.blocks.front().bias(), r.cloth_mean),
                            k.bias.blocks.front().z(), 100.0 * relative(k.bias.level.difference, r.cloth_mean),
                            100.0 * relative(k.bias.level.stderr_difference, r.cloth_mean));
      rows += "\n";
    }
  }
  if (rows.empty()) return {};
  return "\nWhat the error is made of: cloth bias, z of its square (a bias with |z| < 5 is noise), and (level ± its "
         "standard error), % of the mean cloth pixel; "
         "transmission = the albedo-0 image, single = at most one scattering event minus it, multiple = the rest:\n\n"
         "| case | candidate | full | transmission | single | multiple |\n|---|---|---|---|---|---|\n" +
         rows;
}

}  // namespace

double cost_per_sample(const StudyCandidate& c, int pixels) {
  const double samples = static_cast<double>(std::max(1, c.spp)) * std::max(1, pixels);
  return c.cpu_seconds / samples;
}

double speedup_ceiling(const StudyCandidate& c, const StudyCandidate& fine) {
  if (c.factor == 1) return 1.0;                                        // the fine grid against itself
  const double work_c = c.cloth_noise * c.cloth_noise * c.cpu_seconds;  // t_c v_c: t = cpu/spp, v = noise² spp
  const double work_f = fine.cloth_noise * fine.cloth_noise * fine.cpu_seconds;
  return work_c > 0.0 ? work_f / work_c : std::numeric_limits<double>::infinity();
}

double equal_error_speedup(const StudyCandidate& c, const StudyCandidate& fine, double cloth_mean) {
  if (c.factor == 1) return 1.0;  // the fine grid against itself (its bias estimate is noise)
  const double e = kMatrixErrorFraction * cloth_mean;
  if (!(e > 0.0) || c.cloth_bias >= e) return 0.0;
  // t_f v_f / E² over t_c v_c / (E² − b²) = r (1 − b²/E²).
  const double r = speedup_ceiling(c, fine);
  const double share = 1.0 - (c.cloth_bias / e) * (c.cloth_bias / e);
  return std::isinf(r) ? r : r * share;
}

double error_for_speedup(const StudyCandidate& c, const StudyCandidate& fine, double cloth_mean, double target) {
  const double r = speedup_ceiling(c, fine);
  if (c.factor == 1) return target <= 1.0 ? 0.0 : std::numeric_limits<double>::infinity();
  if (!(r > target) || !(cloth_mean > 0.0)) return std::numeric_limits<double>::infinity();
  // r (1 − b²/E²) = target  ⇔  E = b / √(1 − target/r).
  return c.cloth_bias / std::sqrt(1.0 - target / r) / cloth_mean;
}

std::vector<MatrixHeadline> matrix_headlines(const MatrixSpec& spec, const std::vector<MatrixCaseResult>& results) {
  std::vector<MatrixHeadline> out;
  const std::vector<std::string> patterns = matrix_patterns(spec);
  for (std::size_t k = 0; k < patterns.size(); ++k) {
    MatrixHeadline h;
    h.cloth = patterns[k];
    std::map<std::string, std::size_t> index;  // candidate name → verdict
    std::map<std::string, int> counted;
    for (const auto& r : results) {
      if (r.c.cloth != k) continue;
      ++h.judged_cases;
      const MatrixCandidate* fine = fine_entry(r);
      if (fine == nullptr) continue;
      for (const auto& mc : r.candidates) {
        const StudyCandidate& c = mc.study;
        // A representation fitted to this set-up's images is judged only on the others (§6d (b));
        // every other representation is judged on every set-up, the fitted one included.
        if (c.factor == 1 || (r.c.fitted_on && c.fitted_to_images)) continue;
        auto [it, fresh] = index.try_emplace(c.name, h.verdicts.size());
        if (fresh) {
          MatrixVerdict v;
          v.name = c.name;
          v.model = c.model;
          v.factor = c.factor;
          v.worst_relative_bias = -1.0;
          v.speedup = std::numeric_limits<double>::infinity();
          v.speedup_ceiling = std::numeric_limits<double>::infinity();
          v.memory_ratio = mc.memory.values > 0 ? static_cast<double>(fine->memory.values) / mc.memory.values : 0.0;
          h.verdicts.push_back(v);
        }
        MatrixVerdict& v = h.verdicts[it->second];
        take_case(v, r, c.cloth_bias, c.cloth_scales);
        const double f_cost = cost_per_sample(fine->study, r.width * r.height);
        v.cost_ratio += f_cost > 0.0 ? cost_per_sample(c, r.width * r.height) / f_cost : 0.0;
        v.speedup = std::min(v.speedup, equal_error_speedup(c, fine->study, r.cloth_mean));
        v.speedup_ceiling = std::min(v.speedup_ceiling, speedup_ceiling(c, fine->study));
        v.error_for_goal =
            std::max(v.error_for_goal, error_for_speedup(c, fine->study, r.cloth_mean, kMatrixSpeedupGoal));
        ++counted[c.name];
      }
    }
    h.floors = floor_verdicts(spec, results, h.cloth);
    for (auto& v : h.verdicts) {
      const int n = std::max(1, counted[v.name]);
      v.mean_relative_bias /= n;
      v.cost_ratio /= n;
    }
    std::vector<int> factors = spec.study.factors;
    factors.push_back(0);  // the slab
    for (const int f : factors) {
      const MatrixVerdict* best = nullptr;
      for (const auto& v : h.verdicts)
        if (v.factor == f && (best == nullptr || v.worst_relative_bias < best->worst_relative_bias)) best = &v;
      if (best != nullptr) h.best.push_back(*best);
    }
    std::string text = fmt::format("{} ({} set-ups; albedo-corrected judged on the {} it was not fitted on): ", h.cloth,
                                   h.judged_cases, std::max(0, h.judged_cases - 1));
    for (std::size_t i = 0; i < h.best.size(); ++i) {
      const MatrixVerdict& b = h.best[i];
      text += fmt::format(
          "{}{}: {} worst cloth bias {:.1f}% ({}), {:.3g}x fewer bytes, cost/sample {:.2f}x the fine grid's, "
          "speed-up at RMSE 5% {:.2f}x (at most {:.2f}x at any RMSE{})",
          i > 0 ? "; " : "", coarser(b.factor), b.name, 100.0 * b.worst_relative_bias, b.worst_case, b.memory_ratio,
          b.cost_ratio, b.speedup, b.speedup_ceiling, goal_error_text(b.error_for_goal));
    }
    for (const auto& v : h.floors)
      text += fmt::format("; resolution floor at {}: {:.1f}% ({})", coarser(v.factor), 100.0 * v.worst_relative_bias,
                          v.worst_case);
    h.text = text;
    out.push_back(std::move(h));
  }
  return out;
}

std::string matrix_csv(const std::vector<MatrixCaseResult>& results) {
  std::string csv =
      "case,cloth_pattern,lighting,tilt,fitted_on,candidate,model,factor,spp,cloth_pixels,cloth_mean,cloth_bias,"
      "cloth_bias_sq,cloth_bias_sq_stderr,cloth_bias_z,cloth_relative_bias,cloth_rmse,cloth_relative_rmse,cloth_noise,"
      "cloth_difference,bias,bias_z,memory_bytes,memory_channels,memory_ratio,memory_tree_bytes," +
      scale_bias_csv_header() + "," + component_csv_header() + "\n";
  for (const auto& r : results) {
    const MatrixCandidate* fine = fine_entry(r);
    for (const auto& mc : r.candidates) {
      const StudyCandidate& c = mc.study;
      const double ratio =
          fine != nullptr && mc.memory.values > 0 ? static_cast<double>(fine->memory.values) / mc.memory.values : 0.0;
      csv += fmt::format(
          "{},{},{},{},{},{},{},{},{},{},{:.8g},{:.8g},{:.8g},{:.8g},{:.4g},{:.6g},{:.8g},{:.6g},{:.8g},{:.6g},{:.8g}"
          ","
          "{:.4g},{},{},{:.6g},{},{},{}\n",
          r.c.name, r.c.pattern, render::cloth_lighting_name(r.c.lighting), matrix_tilt_name(r.c.tilt),
          r.c.fitted_on ? 1 : 0, c.name, c.model, c.factor, c.spp, r.cloth_pixels, r.cloth_mean, c.cloth_bias,
          c.cloth_bias_sq, c.cloth_bias_sq_stderr, bias_z(c), relative(c.cloth_bias, r.cloth_mean), c.cloth_rmse,
          relative(c.cloth_rmse, r.cloth_mean), c.cloth_noise, c.cloth_difference, c.bias, c.bias_z(), mc.memory.values,
          mc.memory.channels, ratio, mc.memory.tree, scale_bias_csv(c.cloth_scales), component_csv(c.components));
    }
  }
  return csv;
}

std::string matrix_cost_csv(const std::vector<MatrixCaseResult>& results) {
  std::string csv =
      "case,candidate,factor,spp,seconds,cpu_seconds,cpu_seconds_per_sample,cost_ratio,speedup_at_5pct,"
      "speedup_ceiling,error_for_3x\n";
  for (const auto& r : results) {
    const StudyCandidate& fine = fine_of(r);
    const int pixels = r.width * r.height;
    for (const auto& mc : r.candidates) {
      const StudyCandidate& c = mc.study;
      const double f_cost = cost_per_sample(fine, pixels);
      csv += fmt::format("{},{},{},{},{:.6g},{:.6g},{:.6g},{:.4g},{:.4g},{:.4g},{:.4g}\n", r.c.name, c.name, c.factor,
                         c.spp, c.seconds, c.cpu_seconds, cost_per_sample(c, pixels),
                         f_cost > 0.0 ? cost_per_sample(c, pixels) / f_cost : 0.0,
                         equal_error_speedup(c, fine, r.cloth_mean), speedup_ceiling(c, fine),
                         error_for_speedup(c, fine, r.cloth_mean, kMatrixSpeedupGoal));
    }
  }
  return csv;
}

std::string matrix_json(const MatrixSpec& spec, const std::vector<MatrixCaseResult>& results,
                        const std::vector<MatrixHeadline>& headlines) {
  json j;
  j["spec"] = json::parse(matrix_key(spec));
  j["error_fraction"] = kMatrixErrorFraction;
  j["memory"] =
      "bytes = sum over a representation's channels of active voxels x 4 (float); tree_bytes = OpenVDB memUsage";
  j["cases"] = json::array();
  for (const auto& r : results) {
    const StudyCandidate& fine = fine_of(r);
    const MatrixCandidate* fine_mc = fine_entry(r);
    const int pixels = r.width * r.height;
    // The case as it is stored (matrix_case_json), less what depends on timing beyond the
    // "seconds" keys (the curve's seconds), plus what is judged here: "speedup" is the
    // equal-error speed-up, not the single study's.
    json cj = matrix_case_json(r);
    for (std::size_t i = 0; i < r.candidates.size(); ++i) {
      const MatrixCandidate& mc = r.candidates[i];
      const StudyCandidate& c = mc.study;
      json& o = cj["candidates"][i];
      o.erase("curve");
      o["cloth_bias_z"] = bias_z(c);
      o["cloth_relative_bias"] = relative(c.cloth_bias, r.cloth_mean);
      o["cloth_relative_rmse"] = relative(c.cloth_rmse, r.cloth_mean);
      o["memory_ratio"] = fine_mc != nullptr && mc.memory.values > 0
                              ? static_cast<double>(fine_mc->memory.values) / mc.memory.values
                              : 0.0;
      o["sample_cpu_seconds"] = cost_per_sample(c, pixels);
      o["cost_ratio"] = number(cost_per_sample(c, pixels) / std::max(1e-300, cost_per_sample(fine, pixels)));
      o["speedup"] = number(equal_error_speedup(c, fine, r.cloth_mean));
      o["speedup_ceiling"] = number(speedup_ceiling(c, fine));
      o["error_for_3x"] = number(error_for_speedup(c, fine, r.cloth_mean, kMatrixSpeedupGoal));
    }
    j["cases"].push_back(std::move(cj));
  }
  j["headlines"] = json::array();
  for (const auto& h : headlines) {
    json verdicts = json::array();
    const auto verdict = [](const MatrixVerdict& v) {
      return json{{"name", v.name},
                  {"factor", v.factor},
                  {"worst_relative_bias", v.worst_relative_bias},
                  {"worst_case", v.worst_case},
                  {"mean_relative_bias", v.mean_relative_bias},
                  {"memory_ratio", v.memory_ratio},
                  {"cost_ratio", number(v.cost_ratio)},
                  {"speedup", number(v.speedup)},
                  {"speedup_ceiling", number(v.speedup_ceiling)},
                  {"error_for_3x", number(v.error_for_goal)},
                  {"worst_relative_bias_by_block", v.worst_relative_bias_by_block},
                  {"worst_relative_level", v.worst_relative_level}};
    };
    for (const auto& v : h.verdicts) verdicts.push_back(verdict(v));
    json best = json::array();
    for (const auto& v : h.best) best.push_back(verdict(v));
    json floors = json::array();
    for (const auto& v : h.floors) floors.push_back(verdict(v));
    j["headlines"].push_back({{"cloth", h.cloth},
                              {"judged_cases", h.judged_cases},
                              {"best", best},
                              {"representations", verdicts},
                              {"resolution_floors", floors},
                              {"text", h.text}});
  }
  return j.dump(2) + "\n";
}

std::string matrix_markdown(const std::vector<MatrixHeadline>& headlines,
                            const std::vector<MatrixCaseResult>& results) {
  std::string md =
      "| cloth | representation | worst cloth bias | (where) | mean cloth bias | memory (fine / it) | cost per "
      "sample (it / fine) | speed-up at RMSE 5 % | at most (any RMSE) | 3x from RMSE |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& h : headlines) {
    for (const auto& v : h.verdicts) {
      const bool best =
          std::any_of(h.best.begin(), h.best.end(), [&](const MatrixVerdict& b) { return b.name == v.name; });
      md += fmt::format(
          "| {} | {}{}{} | {:.1f} % | {} | {:.1f} % | {:.3g}x | {:.2f} | {:.2f}x | {:.2f}x | {} |\n", h.cloth,
          best ? "**" : "", v.name, best ? "**" : "", 100.0 * v.worst_relative_bias, v.worst_case,
          100.0 * v.mean_relative_bias, v.memory_ratio, v.cost_ratio, v.speedup, v.speedup_ceiling,
          std::isfinite(v.error_for_goal) ? fmt::format("{:.1f} %", 100.0 * v.error_for_goal) : std::string("never"));
    }
  }
  md +=
      "\nGoals (every light x view of a cloth): 4x bias <= 5 %, 8x bias <= 10 %, memory >= 40x at 8x, cost per "
      "sample at 8x <= 0.5 of the fine grid's, speed-up >= 3x at RMSE 5 %. At RMSE E a representation of bias b "
      "is r (1 - b^2/E^2) times faster than the fine grid, r = (fine's cost x variance per sample) / (its own): "
      "never more than r, whatever the accuracy asked.\n\n";
  for (const auto& h : headlines) {
    for (const auto& b : h.best) {
      if (b.factor != 4 && b.factor != 8) continue;
      const double limit = b.factor == 4 ? 0.05 : 0.10;
      std::string goals = fmt::format("bias {:.1f} % {} {:.0f} %", 100.0 * b.worst_relative_bias,
                                      b.worst_relative_bias <= limit ? "<=" : "> (missed)", 100.0 * limit);
      if (b.factor == 8)
        goals += fmt::format("; memory {:.3g}x {}; cost {:.2f} {}", b.memory_ratio,
                             b.memory_ratio >= 40.0 ? "met" : "missed", b.cost_ratio,
                             b.cost_ratio <= 0.5 ? "met" : "missed");
      goals += fmt::format("; speed-up {:.2f}x {} (at most {:.2f}x at any RMSE{})", b.speedup,
                           b.speedup >= kMatrixSpeedupGoal ? "met" : "missed", b.speedup_ceiling,
                           goal_error_text(b.error_for_goal));
      const auto floor =
          std::find_if(h.floors.begin(), h.floors.end(), [&](const MatrixVerdict& f) { return f.factor == b.factor; });
      if (floor != h.floors.end())
        goals += fmt::format("; resolution floor {:.1f} %", 100.0 * floor->worst_relative_bias);
      md += fmt::format("- {} at {}x: best {}: {}\n", h.cloth, b.factor, b.name, goals);
    }
  }
  md += scales_markdown(headlines);
  md += components_markdown(results);
  return md;
}

}  // namespace weft::study
