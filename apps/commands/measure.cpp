// `weft measure`: ground-truth transmittance of beams through a grid (DDA), optionally the
// particle-origin (T_S) vs source-origin (T_Q) rays of the reciprocity check, and the fibre
// ground truth of the same beams (--fibres, docs/validate.md §Fibre ground truth).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "data_gen/cloth/grid_fibres.h"
#include "grid_input.h"
#include "weft/core/atomic_file.h"
#include "weft/core/distinct.h"
#include "weft/core/error.h"
#include "weft/fibres/fibre_beam.h"
#include "weft/render/local_gamma_beam.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/beam.h"
#include "weft/volume/beam_checks.h"
#include "weft/volume/grid.h"
#include "weft/volume/lattice.h"
#include "weft/volume/scatterer.h"
#include "weft/volume/voxel_rule.h"
#include "written_files.h"

namespace weft::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct MeasureOptions {
  GridInputOptions input;
  std::vector<std::string> directions{"x", "y", "z"};
  int rays = 1;
  bool jitter = false;
  double depth_step = 0.0;
  std::string method = "auto";
  std::uint64_t seed = 1;
  bool scatterer = false;
  std::uint64_t scatterer_rays = 100000;
  std::string scatterer_direction;
  std::string out = "weft-out";
  bool fibres = false;
  int fibre_rays = 1;
  double fibre_extinction = 0.0;  // 0: opaque
  std::string voxel_rule = "linear";
  std::string fields;
  std::string memory = "optical-depth";
  bool full_chords = false;
};

std::string num(double x) { return std::isfinite(x) ? fmt::format("{:.10g}", x) : (x < 0 ? "-inf" : "inf"); }

/// The rows of beam b's curve `other` (the fibres' or the fields') beside the voxel beam's on the
/// same depths: beam,dx,dy,dz,t,T_other,stderr_other,T_voxel,stderr_voxel.
void append_beside(std::string& csv, std::size_t b, const volume::TransmittanceCurve& other,
                   const volume::TransmittanceCurve& voxel) {
  for (std::size_t k = 0; k < other.size(); ++k) {
    csv += fmt::format("{},{},{},{},{},{},{},{},{}\n", b, num(other.direction[0]), num(other.direction[1]),
                       num(other.direction[2]), num(other.depth[k]), num(other.transmittance(k)),
                       num(other.stderr_abs(k)), num(voxel.transmittance(k)), num(voxel.stderr_abs(k)));
  }
}

const Registrar kMeasure{Command{
    "measure", "Ground-truth transmittance of beams through a .vdb grid (Amanatides-Woo DDA)", 20,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<MeasureOptions>();
      add_grid_input(sub, o->input, true);
      sub.add_option("--direction", o->directions,
                     "Beam direction, repeatable: x, y, z (optionally signed) or dx,dy,dz")
          ->capture_default_str();
      sub.add_option("--rays", o->rays,
                     "Rays per column (> 1: jittered); oblique beams only: an axis beam's rays of one column "
                     "cross the same voxels (refused when every beam is an axis beam); a beam over 1e12 steps or the "
                     "memory budget is refused before it starts (docs/robustness.md \"Work and memory budgets\")")
          ->capture_default_str();
      sub.add_flag("--jitter", o->jitter, "Jitter ray origins inside their column cell (oblique beams only)");
      sub.add_option("--depth-step", o->depth_step, "Depth spacing of T(t) [length] (default 0: one voxel)")
          ->check(non_negative);
      sub.add_option("--method", o->method, "auto | streaming | per-ray | openvdb")->capture_default_str();
      sub.add_option("--seed", o->seed, "Seed of jittered and scatterer rays")->capture_default_str();
      sub.add_flag("--scatterer", o->scatterer,
                   "Also measure T_S (rays from particles) against p_Q (rays from uniform points)");
      sub.add_option("--scatterer-rays", o->scatterer_rays,
                     "Rays of each kind for --scatterer; a request over 1e12 steps or the memory budget is refused "
                     "before any beam starts (docs/robustness.md \"Work and memory budgets\")")
          ->check(at_least(static_cast<long long>(volume::kMinScattererRays)))
          ->capture_default_str();
      sub.add_option("--scatterer-direction", o->scatterer_direction,
                     "Fixed direction of --scatterer rays (default: isotropic)");
      sub.add_flag("--fibres", o->fibres,
                   "Also trace the beams through the fibres the grid was generated from (regenerated from its "
                   "weft gen provenance), on the same ray lattice: fibres.csv and the voxel-fibre difference");
      sub.add_option("--fibre-rays", o->fibre_rays,
                     "Jittered rays per lattice cell of the fibre beams (--fibres); a beam over 1e12 steps is refused "
                     "before it starts (docs/robustness.md \"Work and memory budgets\")")
          ->capture_default_str();
      sub.add_option("--fibre-extinction", o->fibre_extinction,
                     "Extinction inside the fibres [1/length] for --fibres (default: opaque fibres)");
      sub.add_option("--voxel-rule", o->voxel_rule,
                     "How concentration becomes extinction in the voxel beams: linear (sigma C) | opaque "
                     "(-max(sigma, 1/h) ln(1 - C), docs/validate.md)")
          ->capture_default_str();
      sub.add_flag("--full-chords", o->full_chords,
                   "Oblique beams: trace only the rays that cross the grid's box from face to opposite face "
                   "(the whole depth), not those entering or leaving through a side, whose short chords dilute "
                   "a comparison (--fibres, --fields) with T near 1 (docs/validate.md \"Fields along any "
                   "direction\")");
      sub.add_option("--fields", o->fields,
                     "Also predict every beam from local-gamma fields of this grid (weft fit --block B's "
                     "local_fields.vdb), along the same rays, as the render's local-gamma medium walks them: "
                     "fields.csv and the fields-voxel difference (docs/validate.md \"Fields along any direction\")")
          ->check(file_name)
          ->check(CLI::ExistingFile);
      sub.add_option("--memory", o->memory,
                     "Memory rule across the fields' cells for --fields: optical-depth | segment | renewal | carried "
                     "(docs/render.md 5e)")
          ->capture_default_str();
      sub.add_option("--out", o->out,
                     "Output folder (created if missing): beams.csv, measure.json, scatterer.csv with --scatterer, "
                     "fibres.csv with --fibres, fields.csv with --fields")
          ->capture_default_str();
      return [o, &sub](const Context& ctx) -> int {
        const auto t_start = std::chrono::steady_clock::now();
        check_grid_input(o->input);
        usage_needs(sub, {"--scatterer-rays", "--scatterer-direction"}, o->scatterer, "--scatterer");
        usage_needs(sub, {"--fibre-rays", "--fibre-extinction"}, o->fibres, "--fibres");
        usage_needs(sub, {"--memory"}, !o->fields.empty(), "--fields");
        // Only random rays read the seed: jittered columns, the scatterer's, the fibres' jitter.
        usage_needs(sub, {"--seed"}, o->jitter || o->rays > 1 || o->scatterer || (o->fibres && o->fibre_rays > 1),
                    "random rays (--jitter, --rays above 1, --scatterer or --fibre-rays above 1)");
        std::vector<std::array<double, 3>> dirs;
        for (const auto& d : o->directions) dirs.push_back(as_usage([&] { return volume::parse_direction(d); }));
        // A direction given twice would trace the same rays again (same seed, same curve).
        as_usage([&] {
          require_distinct(
              "--direction", dirs,
              [&](std::size_t i) { return fmt::format("beam {}", volume::direction_label(dirs[i])); },
              [](const std::array<double, 3>& d) { return volume::unit_direction(d, "beam"); });
        });
        const auto method = as_usage([&] { return volume::parse_beam_method(o->method); });
        as_usage([&] { volume::check_beam_method(method, dirs, FrontEnd::cli); });
        // An axis beam's rays all cross the whole box: the flag would change nothing (the rule
        // Python shares).
        as_usage([&] { volume::check_full_chords(dirs, o->full_chords, FrontEnd::cli); });
        const std::array<double, 3> scatterer_direction =
            o->scatterer_direction.empty() ? std::array<double, 3>{0.0, 0.0, 1.0}
                                           : as_usage([&] { return volume::parse_direction(o->scatterer_direction); });
        // More rays per column or jitter are refused when every beam is an axis beam (the rule
        // Python shares) and noted per axis beam otherwise.
        as_usage([&] { volume::check_rays_per_column(dirs, o->rays, o->jitter, FrontEnd::cli); });
        const auto rule = as_usage([&] { return volume::parse_voxel_rule(o->voxel_rule); });
        if (rule != volume::VoxelRule::linear && o->input.extinction())
          usage_fail("--voxel-rule {} needs concentration values, not --values extinction", o->voxel_rule);
        if (o->fibre_rays < 1) usage_fail("--fibre-rays must be >= 1, got {}", o->fibre_rays);
        const bool fibre_extinction_given = sub.count("--fibre-extinction") > 0;
        if (fibre_extinction_given && !(o->fibre_extinction > 0.0))
          usage_fail("--fibre-extinction must be > 0, got {}", o->fibre_extinction);
        const auto memory = transmittance::parse_memory_rule(o->memory);
        if (!memory)
          usage_fail("--memory: unknown memory rule '{}' (optical-depth, segment, renewal, carried)", o->memory);
        if (!o->fields.empty() && rule != volume::VoxelRule::linear)
          usage_fail(
              "--fields predicts the linear rule's extinction (sigma C of the fields' means), not --voxel-rule {}",
              o->voxel_rule);
        const LoadedGrid loaded = load_grid_input(o->input);
        // Every beam's full chords before any beam is traced: a beam whose lattice would keep no
        // ray (its voxel and fields rays, and its fibre rays) is refused here, not after the others.
        if (o->full_chords) {
          const volume::WorldBox box = volume::active_world_box(loaded.grid);
          for (const auto& d : dirs) {
            volume::BeamSpec fc;
            fc.direction = d;
            fc.full_chords = true;
            fc.rays_per_column = o->rays;
            as_usage([&] { volume::check_full_chord_rays(box, loaded.grid.voxel_size(), fc, FrontEnd::cli); });
            fc.rays_per_column = o->fibre_rays;
            if (o->fibres)
              as_usage([&] { volume::check_full_chord_rays(box, loaded.grid.voxel_size(), fc, FrontEnd::cli); });
          }
        }
        std::optional<render::CheckedFields> fields;
        if (!o->fields.empty()) {
          // The fields read and checked against the grid, and every fields beam's budget, before
          // the fibres are made and any beam runs (--fields keeps the linear rule: the grid as read).
          for (const auto& d : dirs) {
            volume::BeamSpec fs;
            fs.direction = d;
            fs.rays_per_column = o->rays;
            fs.jitter = o->jitter;
            fs.depth_step = o->depth_step;
            fs.full_chords = o->full_chords;
            render::check_fields_beam(loaded.grid, fs);
          }
          fields.emplace(
              render::check_fields({o->fields, loaded.sigma.sigma, o->input.extinction(), *memory}, loaded.grid));
        }
        // The fibres first: a grid that does not name its fibres is refused before any beam.
        std::optional<fibres::CapsuleIndex> fibre_index;
        const auto fibre_spec = [&](const std::array<double, 3>& d) {
          volume::BeamSpec fs;
          fs.direction = d;
          fs.seed = o->seed;
          fs.depth_step = o->depth_step;
          fs.rays_per_column = o->fibre_rays;
          fs.jitter = o->fibre_rays > 1;
          fs.full_chords = o->full_chords;
          return fs;
        };
        if (o->fibres) {
          // Every fibre beam's budget before any beam runs (the voxel beams check their own).
          for (const auto& d : dirs) fibres::check_fibre_beam(loaded.grid, fibre_spec(d));
          fibre_index.emplace(cloth::fibre_geometry(cloth::fibers_of_grid(loaded.grid, o->input.grid, ctx.progress)));
        }
        const bool ruled = rule != volume::VoxelRule::linear;
        const volume::Grid grid = ruled ? volume::extinction_grid(loaded.grid, loaded.sigma.sigma, rule) : loaded.grid;
        const double sigma = ruled ? 1.0 : loaded.sigma.sigma;
        const std::string values =
            ruled ? fmt::format("{} ({} voxel rule)", o->input.values, o->voxel_rule) : o->input.values;
        const double fibre_kappa = fibre_extinction_given ? o->fibre_extinction : fibres::kOpaque;

        // The scatterer rays' budget before any beam runs (docs/robustness.md "Work and memory budgets").
        volume::ScattererSpec ss;
        ss.scale = sigma;
        ss.rays = o->scatterer_rays;
        ss.seed = o->seed;
        ss.depth_step = o->depth_step;
        ss.fixed_direction = !o->scatterer_direction.empty();
        if (ss.fixed_direction) ss.direction = scatterer_direction;
        if (o->scatterer) volume::check_scatterer(grid, ss);

        // The first line records σ and the grid, so `weft fit --beams` can refuse curves of another σ or grid.
        std::string csv = beams_record_line({sigma, values, grid.voxel_size(), grid.active_voxel_count(), grid.sum()}) +
                          "beam,dx,dy,dz,t,T,stderr,logT\n";
        json beams = json::array();
        std::string fibre_csv = "beam,dx,dy,dz,t,T_fibre,stderr_fibre,T_voxel,stderr_voxel\n";
        std::string fields_csv = "beam,dx,dy,dz,t,T_fields,stderr_fields,T_voxel,stderr_voxel\n";
        for (std::size_t b = 0; b < dirs.size(); ++b) {
          volume::BeamSpec spec;
          spec.direction = dirs[b];
          spec.scale = sigma;
          spec.rays_per_column = o->rays;
          spec.jitter = o->jitter;
          spec.seed = o->seed;
          spec.depth_step = o->depth_step;
          spec.method = method;
          spec.full_chords = o->full_chords;
          const auto t0 = std::chrono::steady_clock::now();
          const auto curve = volume::measure_beam(grid, spec, ctx.progress);
          const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          for (std::size_t k = 0; k < curve.size(); ++k) {
            csv += fmt::format("{},{},{},{},{},{},{},{}\n", b, num(curve.direction[0]), num(curve.direction[1]),
                               num(curve.direction[2]), num(curve.depth[k]), num(curve.transmittance(k)),
                               num(curve.stderr_abs(k)), num(curve.log_t[k]));
          }
          beams.push_back({{"beam", b},
                           {"direction", volume::direction_label(curve.direction)},
                           {"rays", curve.distinct_rays},
                           {"rays_traced", curve.rays},
                           {"method", curve.method},
                           {"depth_max", curve.depth.back()},
                           {"T_at_depth_max", curve.transmittance(curve.size() - 1)},
                           {"logT_at_depth_max", curve.log_t.back()},
                           {"seconds", secs}});
          if (fibre_index) {
            const volume::BeamSpec fs = fibre_spec(dirs[b]);
            const auto f0 = std::chrono::steady_clock::now();
            const auto fc = fibres::measure_fibre_beam(*fibre_index, grid, fs, fibre_kappa, ctx.progress);
            const double fsecs = std::chrono::duration<double>(std::chrono::steady_clock::now() - f0).count();
            append_beside(fibre_csv, b, fc, curve);
            const auto diff = fibres::curve_difference(curve, fc);
            beams.back()["fibres"] = {{"rays", fc.rays},
                                      {"method", fc.method},
                                      {"T_fibre_at_depth_max", diff.end_b},
                                      {"rms_T_voxel_minus_T_fibre", diff.rms},
                                      {"max_abs_T_voxel_minus_T_fibre", diff.max_abs},
                                      {"rms_stderr_fibre", diff.rms_stderr_b},
                                      {"seconds", fsecs}};
          }
          if (fields) {
            const auto f0 = std::chrono::steady_clock::now();
            const auto pc = render::predict_fields_beam(*fields, grid, spec, ctx.progress);
            const double fsecs = std::chrono::duration<double>(std::chrono::steady_clock::now() - f0).count();
            append_beside(fields_csv, b, pc, curve);
            const auto diff = fibres::curve_difference(curve, pc);
            const std::size_t last = pc.size() - 1;
            beams.back()["fields"] = {
                {"rays", pc.rays},
                {"method", pc.method},
                {"T_fields_at_depth_max", diff.end_b},
                {"relative_difference_at_depth_max", diff.end_b / diff.end_a - 1.0},
                {"relative_difference_stderr",
                 std::hypot(pc.rel_stderr[last], curve.rel_stderr[last]) * (diff.end_b / diff.end_a)},
                {"rms_T_fields_minus_T_voxel", diff.rms},
                {"max_abs_T_fields_minus_T_voxel", diff.max_abs},
                {"seconds", fsecs}};
          }
        }
        std::string scatterer_csv;
        json scatterer = nullptr;
        if (o->scatterer) {
          const auto t0 = std::chrono::steady_clock::now();
          const auto c = volume::measure_scatterer(grid, ss, ctx.progress);
          scatterer_csv = "t,T_S,T_S_stderr,T_Q,T_Q_stderr,p_Q,mu_bar_T_S\n";
          double worst = 0.0;
          for (std::size_t k = 0; k < c.t_s.size(); ++k) {
            scatterer_csv += fmt::format("{},{},{},{},{},{},{}\n", num(c.t_s.depth[k]), num(c.t_s.transmittance(k)),
                                         num(c.t_s.stderr_abs(k)), num(c.t_q.transmittance(k)),
                                         num(c.t_q.stderr_abs(k)), num(c.p_q[k]), num(c.mu_t_s[k]));
            worst = std::max(worst, std::abs(c.p_q[k] - c.mu_t_s[k]) / std::max(c.mean_extinction, 1e-300));
          }
          scatterer = {{"rays", ss.rays},
                       {"directions", ss.fixed_direction ? o->scatterer_direction : "isotropic"},
                       {"mean_extinction", c.mean_extinction},
                       {"max_abs_pQ_minus_mu_TS_over_mu", worst},
                       {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
        }
        json report = {
            {"weft", "measure"},
            {"grid", fs::absolute(o->input.grid).string()},
            {"grid_name", grid.name()},
            {"values", values},
            {"voxel_rule", o->voxel_rule},
            {"fibres",
             o->fibres ? json(fibre_kappa == fibres::kOpaque ? json("opaque") : json(fibre_kappa)) : json(nullptr)},
            {"fields", o->fields.empty() ? json(nullptr)
                                         : json{{"file", fs::absolute(o->fields).string()}, {"memory", o->memory}}},
            {"sigma", sigma},
            {"sigma_source", loaded.sigma.source},
            {"voxel_size", grid.voxel_size()},
            {"active_voxels", grid.active_voxel_count()},
            {"seed", o->seed},
            {"full_chords", o->full_chords},
            {"beams", beams},
            {"scatterer", scatterer}};
        const fs::path out = o->out;
        // Its files appear together, or the folder stays as it was (docs/robustness.md "Output
        // folders of failed runs").
        FolderRollback written(out);
        WrittenFiles files;
        write_text_atomically(out / "beams.csv", csv);
        files.add(out / "beams.csv", "T(t) per beam");
        if (o->fibres) {
          write_text_atomically(out / "fibres.csv", fibre_csv);
          files.add(out / "fibres.csv", "T_fibre(t) and T_voxel(t) per beam");
        }
        if (!o->fields.empty()) {
          write_text_atomically(out / "fields.csv", fields_csv);
          files.add(out / "fields.csv", "T_fields(t) and T_voxel(t) per beam");
        }
        if (o->scatterer) {
          write_text_atomically(out / "scatterer.csv", scatterer_csv);
          files.add(out / "scatterer.csv", "T_S, T_Q, p_Q");
        }
        report["seconds_total"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
        report["outputs"] = files.to_json(out);
        write_text_atomically(out / "measure.json", report.dump(2) + "\n");
        files.add(out / "measure.json", "report");
        written.keep();
        for (const auto& b : beams) {
          const auto traced = b["rays_traced"].get<std::uint64_t>();
          const auto distinct = b["rays"].get<std::uint64_t>();
          if (traced != distinct)
            ctx.say(fmt::format("note: beam {}: {} rays per column cross the same voxels; {} distinct rays",
                                b["direction"].get<std::string>(), o->rays, distinct));
          ctx.say(fmt::format("beam {:<24} rays {:>9}  T({:.4g}) = {:.4e} (log T = {:.4g})  {:.2f}s [{}]",
                              b["direction"].get<std::string>(), distinct, b["depth_max"].get<double>(),
                              b["T_at_depth_max"].get<double>(), b["logT_at_depth_max"].get<double>(),
                              b["seconds"].get<double>(), b["method"].get<std::string>()));
          if (b.contains("fibres")) {
            const auto& f = b["fibres"];
            ctx.say(fmt::format(
                "  fibres {:>9} rays  T = {:.4e}  voxel - fibre: RMS {:.4f} max {:.4f} (noise {:.4f})  "
                "{:.2f}s",
                f["rays"].get<std::uint64_t>(), f["T_fibre_at_depth_max"].get<double>(),
                f["rms_T_voxel_minus_T_fibre"].get<double>(), f["max_abs_T_voxel_minus_T_fibre"].get<double>(),
                f["rms_stderr_fibre"].get<double>(), f["seconds"].get<double>()));
          }
          if (b.contains("fields")) {
            // T_fields beside the beam's own line, as the fibres' (docs/validate.md "Fields along any direction").
            const auto& f = b["fields"];
            ctx.say(fmt::format(
                "  fields {:>9} rays  T = {:.4e}  fields/voxel - 1 = {:+.4f} +- {:.4f}  RMS {:.4f} max "
                "{:.4f}  {:.2f}s [{}]",
                f["rays"].get<std::uint64_t>(), f["T_fields_at_depth_max"].get<double>(),
                f["relative_difference_at_depth_max"].get<double>(), f["relative_difference_stderr"].get<double>(),
                f["rms_T_fields_minus_T_voxel"].get<double>(), f["max_abs_T_fields_minus_T_voxel"].get<double>(),
                f["seconds"].get<double>(), f["method"].get<std::string>()));
          }
        }
        if (o->scatterer) {
          ctx.say(fmt::format("scatterer rays: max |p_Q - mu T_S|/mu = {:.3g}",
                              scatterer["max_abs_pQ_minus_mu_TS_over_mu"].get<double>()));
        }
        files.say(ctx);
        return 0;
      };
    }}};

}  // namespace
}  // namespace weft::app
