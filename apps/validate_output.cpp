#include "validate_output.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "validate_common.h"
#include "weft/fit/report.h"

namespace weft::app {

std::string curves_csv(const fit::Validation& v, const std::vector<volume::TransmittanceCurve>* fibre) {
  std::size_t rows = 0;
  const fit::AxisValidation* longest = nullptr;
  for (const auto& a : v.axes) {
    if (a.ground_truth.size() > rows) {
      rows = a.ground_truth.size();
      longest = &a;
    }
  }
  std::string out = "t";
  for (const auto& a : v.axes) {
    out += fmt::format(",T_gt_{0},stderr_{0},logT_gt_{0}", a.label);
    if (fibre != nullptr) out += fmt::format(",T_fibre_{0},stderr_fibre_{0}", a.label);
    for (const auto& m : a.models) out += fmt::format(",{}_{}", m.name, a.label);
  }
  out += "\n";
  for (std::size_t k = 0; k < rows; ++k) {
    out += fmt_csv(longest->ground_truth.depth[k]);
    for (std::size_t i = 0; i < v.axes.size(); ++i) {
      const auto& a = v.axes[i];
      const auto& gt = a.ground_truth;
      if (k < gt.size()) {
        out += fmt::format(",{},{},{}", fmt_csv(gt.transmittance(k)), fmt_csv(gt.stderr_abs(k)), fmt_csv(gt.log_t[k]));
        // The fibre beam runs on the voxel beam's rays and depths (docs/validate.md "Fibre ground truth").
        if (fibre != nullptr)
          out += fmt::format(",{},{}", fmt_csv((*fibre)[i].transmittance(k)), fmt_csv((*fibre)[i].stderr_abs(k)));
        for (const auto& m : a.models) out += fmt::format(",{}", fmt_csv(std::exp(m.log_t[k])));
      } else {
        out += fibre != nullptr ? ",,,,," : ",,,";
        for (std::size_t i = 0; i < a.models.size(); ++i) out += ",";
      }
    }
    out += "\n";
  }
  return out;
}

ModelStyle model_style(const std::string& m) {
  using viz::LineStyle;
  using viz::Marker;
  if (m == "gamma") return {{230, 120, 0}, LineStyle::dashed, Marker::none};
  if (m == "empirical") return {{150, 110, 60}, LineStyle::dotted, Marker::none};
  if (m == "gap-gamma") return {{200, 0, 160}, LineStyle::dash_dot, Marker::none};
  if (m == "across-beam") return {{0, 150, 150}, LineStyle::dotted, Marker::none};
  if (m == "local-exponential") return {{120, 120, 120}, LineStyle::dashed, Marker::none};
  if (m == "local-gamma") return {{0, 0, 0}, LineStyle::solid, Marker::none};
  if (m == "local-gamma-renewal") return {{120, 200, 90}, LineStyle::dash_dot, Marker::none};
  if (m == fit::kPredictedModel) return {{230, 0, 90}, LineStyle::solid, Marker::none};
  if (m == "least-squares") return {{160, 140, 0}, LineStyle::dotted, Marker::none};
  if (m == "isotropic") return {{160, 160, 220}, LineStyle::dotted, Marker::none};
  return {{140, 40, 180}, LineStyle::solid, Marker::none};  // exponential
}

viz::RenderOutcome save_transmittance_figure(const fit::Validation& v, const std::string& title,
                                             const std::string& units, const std::filesystem::path& path,
                                             const std::vector<volume::TransmittanceCurve>* fibres) {
  std::vector<viz::Chart> panels;
  for (const auto& a : v.axes) {
    viz::Chart c;
    if (!fit::ratios_undefined(a).empty()) {
      c.title = fmt::format("beam {}: the exponential is exact (its error is rounding)", a.label);
    } else if (v.models.wants(fit::kPredictedModel)) {
      const auto p = fit::predicted(a);
      c.title = fmt::format("beam {}: predicted ({}) {:.2f} of the exponential's error", a.label, p.name, p.ratio);
    } else {
      c.title = fmt::format("beam {}: models {}", a.label, v.models.text());
    }
    c.x_label = fmt::format("depth t [{}]", units);
    c.y_label = "transmittance T(t)";
    c.log_y = true;
    c.width = 900;
    c.height = 640;
    const auto& gt = a.ground_truth;
    double tmin = 1.0;
    viz::Band band;
    band.label = "ground truth +- 2 s.e.";
    band.color = axis_color(a.direction);
    band.x = gt.depth;
    viz::Series g;
    g.label = fmt::format("ground truth {}", a.label);
    g.color = axis_color(a.direction);
    g.width = 3.5f;
    g.x = gt.depth;
    for (std::size_t k = 0; k < gt.size(); ++k) {
      const double T = gt.transmittance(k);
      g.y.push_back(T);
      band.lower.push_back(std::max(T - 2.0 * gt.stderr_abs(k), 0.5 * T));
      band.upper.push_back(T + 2.0 * gt.stderr_abs(k));
      if (T > 0.0) tmin = std::min(tmin, T);
    }
    c.bands.push_back(band);
    for (const auto& m : a.models) {
      if (m.name == "isotropic") continue;  // one law for all axes: in report.json and curves.csv
      const auto st = model_style(m.name);
      viz::Series s;
      s.label = m.uses_ground_truth ? fmt::format("{} (reference, fitted to T_gt)", m.name) : m.name;
      s.color = st.color;
      s.style = st.style;
      s.marker = st.marker;
      s.width = m.name == "gamma" || m.name == fit::kPredictedModel ? 3.0f : 2.0f;
      for (std::size_t k = 0; k < gt.size(); ++k) {
        s.x.push_back(gt.depth[k]);
        s.y.push_back(std::exp(m.log_t[k]));
        if (m.name != "exponential") tmin = std::min(tmin, std::max(1e-12, s.y.back()));
      }
      c.series.push_back(s);
    }
    c.series.insert(c.series.begin(), g);
    // --- weft validate --fibres: the fibre ground truth on the same rays (validate_fibres.h) ---
    if (fibres != nullptr && panels.size() < fibres->size()) {
      const auto& fc = (*fibres)[panels.size()];
      viz::Series f;
      f.label = fmt::format("fibres {} (opaque)", a.label);
      f.color = axis_color(a.direction);
      f.style = viz::LineStyle::dotted;
      f.width = 2.0f;
      f.x = fc.depth;
      for (std::size_t k = 0; k < fc.size(); ++k) f.y.push_back(std::max(1e-12, fc.transmittance(k)));
      c.series.insert(c.series.begin() + 1, f);
    }
    c.y_range = std::make_pair(std::max(1e-6, std::min(1e-2, 0.5 * tmin)), 1.15);
    c.x_range = std::make_pair(0.0, gt.depth.back());
    panels.push_back(std::move(c));
  }
  const int columns = panels.size() <= 3 ? static_cast<int>(panels.size()) : 3;
  return viz::save_chart_grid_png(panels, std::max(1, columns), path,
                                  fmt::format("{}: transmittance, sigma = {:.4g}/{}", title, v.sigma, units));
}

namespace {

/// A ratio to the exponential, or "n/a" where it is undefined (fit::ratios_undefined).
std::string ratio_text(double ratio) { return std::isfinite(ratio) ? fmt::format("{:.3f}", ratio) : "n/a"; }

}  // namespace

std::vector<std::string> summary_table(const fit::Validation& v) {
  std::vector<std::string> lines;
  if (v.axes.empty()) return lines;
  std::string head = fmt::format("{:<20}", "model (RMS err T)");
  for (const auto& a : v.axes) head += fmt::format(" {:>10} {:>6}", a.label, "/exp");
  head += "  uses T_gt";
  lines.push_back(head);
  for (std::size_t i = 0; i < v.axes.front().models.size(); ++i) {
    const auto& name = v.axes.front().models[i].name;
    std::string row = fmt::format("{:<20}", name);
    for (const auto& a : v.axes) {
      const auto ratios = fit::model_ratios(a);
      const auto& r = ratios[i];
      row += fmt::format(" {:>10.3e} {:>6}", r.rms_abs_t, ratio_text(r.ratio));
    }
    row += v.axes.front().models[i].uses_ground_truth ? "  yes (reference)" : "  no";
    lines.push_back(row);
  }
  const bool has_prediction = v.models.wants(fit::kPredictedModel);
  std::string predicted = fmt::format("predicted ({}, fixed before measuring):", fit::kPredictedModel);
  std::string best = "best model chosen with the ground truth (diagnostic):";
  std::string exact;  // the axes whose ratios are undefined, and why (fit::ratios_undefined)
  std::string why;
  for (const auto& a : v.axes) {
    const std::string reason = fit::ratios_undefined(a);
    const bool undefined = !reason.empty();
    if (undefined) {
      exact += " " + a.label;
      why = reason;
    }
    if (has_prediction) {
      const auto p = fit::predicted(a);
      predicted += fmt::format(" {} {}{}", a.label, ratio_text(p.ratio),
                               undefined || p.ratio <= 1.0 / 3.0 ? "" : " (misses 1/3)");
    }
    const auto b = fit::best_by_ground_truth(a);
    best += fmt::format(" {} {} {}", a.label, b.name, ratio_text(b.ratio));
  }
  if (has_prediction) lines.push_back(predicted);
  lines.push_back(best);
  if (!exact.empty()) lines.push_back(fmt::format("ratios /exp undefined on{}: {}", exact, why));
  return lines;
}

}  // namespace weft::app
