// `weft validate --sweep`: accuracy vs time of fewer rays and coarse-grid models (docs/validate.md),
// written as accuracy_time.csv, sweep.json and accuracy_time.png.
#include <algorithm>
#include <filesystem>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "validate_common.h"
#include "validate_sweep.h"
#include "weft/core/atomic_file.h"
#include "weft/dist/distributed.h"
#include "weft/dist/unit_store.h"
#include "weft/study/sweep.h"
#include "weft/viz/chart.h"
#include "weft/viz/display.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

/// accuracy_time.csv: one row per (axis, method, factor, ray fraction).
std::string sweep_csv(const study::Sweep& s) {
  std::string out =
      "axis,method,factor,ray_fraction,rays,error_rms_T,error_max_T,stderr_rms_T,accuracy_rms_T,prepare_seconds,"
      "transport_seconds,seconds,pareto\n";
  for (const auto& r : s.rows) {
    out +=
        fmt::format("{},{},{},{:.6g},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{}\n", r.axis, r.method, r.factor,
                    r.ray_fraction, r.rays, fmt_csv(r.error_rms_t), fmt_csv(r.error_max_t), fmt_csv(r.stderr_rms_t),
                    fmt_csv(r.accuracy_rms_t), r.prepare_seconds, r.transport_seconds, r.seconds(), r.pareto ? 1 : 0);
  }
  return out;
}

/// Error vs time, log–log: a marker shape per method, a colour per axis, each point annotated
/// with its coarsening factor (models) or ray fraction (ground truth); the Pareto front of each
/// axis as a dashed line. Automatic ranges keep a margin, so no point touches the frame.
viz::Chart sweep_chart(const study::Sweep& s, const std::string& title) {
  viz::Chart c;
  c.title = title + ": accuracy vs time (labels: grid coarsening / ray fraction; dashed: Pareto fronts)";
  c.x_label = "time [s] (preparation + transport, median)";
  c.y_label = "RMS error of T (models: vs reference; rays: standard error)";
  c.log_x = true;
  c.log_y = true;
  c.width = 1300;
  c.height = 850;
  const std::vector<std::pair<std::string, viz::Marker>> methods{{"ground-truth", viz::Marker::circle},
                                                                 {"exponential", viz::Marker::square},
                                                                 {"gamma", viz::Marker::diamond},
                                                                 {"gamma-memory", viz::Marker::cross}};
  const std::vector<std::string> axes{"+x", "+y", "+z", "-x", "-y", "-z"};
  for (const auto& [m, marker] : methods) {
    for (const std::string& axis : axes) {
      viz::Series ser;
      ser.label = fmt::format("{} {}", m == "ground-truth" ? "ground truth, fewer rays" : m + " on coarse grid", axis);
      ser.color = axis_color(fit::parse_axes(axis).front());
      ser.style = viz::LineStyle::markers;
      ser.marker = marker;
      ser.width = 3.0f;
      for (const auto& r : s.rows) {
        if (r.method != m || r.axis != axis || !(r.accuracy_rms_t > 0.0)) continue;
        ser.x.push_back(r.seconds());
        ser.y.push_back(r.accuracy_rms_t);
        const std::string text =
            m == "ground-truth"
                ? (r.ray_fraction >= 1.0 ? std::string("all rays") : fmt::format("1/{:.0f}", 1.0 / r.ray_fraction))
                : fmt::format("\u00d7{}", r.factor);
        c.annotations.push_back({r.seconds(), r.accuracy_rms_t, text, ser.color});
      }
      if (!ser.x.empty()) c.series.push_back(ser);
    }
  }
  for (const std::string& axis : axes) {
    std::vector<std::pair<double, double>> front;
    for (const auto& r : s.rows) {
      if (r.axis == axis && r.pareto && r.accuracy_rms_t > 0.0) front.emplace_back(r.seconds(), r.accuracy_rms_t);
    }
    if (front.empty()) continue;
    std::sort(front.begin(), front.end());
    viz::Series f;
    f.color = axis_color(fit::parse_axes(axis).front());
    f.style = viz::LineStyle::dashed;
    f.width = 1.5f;
    for (const auto& [x, y] : front) {
      f.x.push_back(x);
      f.y.push_back(y);
    }
    c.series.push_back(f);
  }
  return c;
}

}  // namespace

/// `weft validate --sweep`: the accuracy/time table, written after everything is computed.
int run_sweep(const SweepOutputOptions& o, const Context& ctx, const volume::Grid& grid,
              const fit::ValidationSpec& vspec, const std::string& title, json input, json timings,
              std::chrono::steady_clock::time_point t_start) {
  study::SweepSpec spec;
  spec.directions = vspec.directions;
  spec.sigma = vspec.sigma;
  spec.seed = vspec.seed;
  spec.repetitions = o.quick ? 1 : 3;
  const fs::path out = o.out;
  // Each finished unit is recorded in <out>/units/ (rank 0), so a run that dies can be finished
  // with --resume; the key is everything the units' bytes depend on.
  const json key = {{"weft", "validate --sweep"},
                    {"input", input},
                    {"axes", o.axes},
                    {"sigma", spec.sigma},
                    {"seed", spec.seed},
                    {"repetitions", spec.repetitions},
                    {"factors", spec.factors},
                    {"ray_strides", spec.ray_strides},
                    // Where the coarse blocks fall (docs/render.md §5 "Coarse grids anchored to
                    // the cloth"): a store made with the index-aligned blocks is refused.
                    {"coarse_blocks", "anchored"}};
  dist::UnitStore store(out / "units", key.dump(2) + "\n", o.resume);
  if (dist::is_root()) ensure_directory(out);
  auto t0 = std::chrono::steady_clock::now();
  const study::Sweep s = study::sweep(grid, spec, ctx.progress, &store);
  if (!dist::is_root()) return 0;  // rank 0 gathered every unit and writes
  timings["sweep"] = seconds_since(t0);
  const std::string csv = sweep_csv(s);
  write_text_atomically(out / "accuracy_time.csv", csv);
  json outputs = {{"accuracy_time.csv", "written"}};
  if (o.no_plot) {
    outputs["accuracy_time.png"] = "skipped: --no-plot";
  } else {
    t0 = std::chrono::steady_clock::now();
    std::string why;
    if (!viz::ensure_display(&why)) {
      outputs["accuracy_time.png"] = fmt::format("not rendered: {}", why);
    } else {
      const auto chart = viz::save_chart_png(sweep_chart(s, title), out / "accuracy_time.png");
      outputs["accuracy_time.png"] =
          chart.written ? std::string("written") : fmt::format("not rendered: {}", chart.reason);
    }
    timings["plots"] = seconds_since(t0);
  }
  timings["total"] = seconds_since(t_start);
  input["voxel_size"] = grid.voxel_size();
  input["active_voxels"] = grid.active_voxel_count();
  json report = {{"weft", "validate --sweep"},      {"input", input},       {"sigma", spec.sigma},
                 {"repetitions", spec.repetitions}, {"ranks", ctx.ranks()}, {"threads", ctx.threads()},
                 {"resumed_units", store.found()},  {"outputs", outputs},   {"timings_seconds", timings}};
  write_text_atomically(out / "sweep.json", report.dump(2) + "\n");
  store.remove();  // the outputs are whole: the finished units are no longer needed

  ctx.say(fmt::format(
      "weft validate --sweep: {}; sigma = {:.6g}/length, {} active voxels of {:.4g}; times are "
      "medians of {} run(s); {} rank(s) x {} thread(s){}",
      title, spec.sigma, grid.active_voxel_count(), grid.voxel_size(), spec.repetitions, ctx.ranks(), ctx.threads(),
      store.found() > 0 ? fmt::format("; {} unit(s) resumed from {}", store.found(), store.folder().string())
                        : std::string()));
  ctx.say(fmt::format("{:<5} {:<13} {:>6} {:>8} {:>9} {:>11} {:>11} {:>11} {:>10} {:>10}  {}", "axis", "method",
                      "factor", "ray frac", "rays", "RMS err T", "max err T", "RMS s.e. T", "prepare s", "beam s",
                      "pareto"));
  for (const auto& r : s.rows) {
    ctx.say(fmt::format("{:<5} {:<13} {:>6} {:>8.4g} {:>9} {:>11.3e} {:>11.3e} {:>11.3e} {:>10.4f} {:>10.4f}  {}",
                        r.axis, r.method, r.factor, r.ray_fraction, r.rays, r.error_rms_t, r.error_max_t,
                        r.stderr_rms_t, r.prepare_seconds, r.transport_seconds, r.pareto ? "*" : ""));
  }
  for (auto it = outputs.begin(); it != outputs.end(); ++it) {
    const std::string status = it.value().get<std::string>();
    if (status != "written" && status.find("--no-plot") == std::string::npos)
      fmt::print(stderr, "weft validate: note: {} {}\n", it.key(), status);
  }
  ctx.say(fmt::format("wrote {}", (out / "accuracy_time.csv").string()));
  return 0;
}

}  // namespace weft::app
