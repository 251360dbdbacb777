#include "data_gen/cloth/cloth.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <fmt/format.h>

#include "data_gen/cloth/grid_fibres.h"
#include "data_gen/cloth/pattern.h"
#include "data_gen/cloth/voxelize.h"
#include "data_gen/cloth/yarn.h"
#include "weft/core/error.h"
#include "weft/core/file_kind.h"
#include "weft/core/memory.h"
#include "weft/core/parallel.h"
#include "weft/core/paths.h"
#include "weft/dist/distributed.h"
#include "weft/volume/provenance.h"

namespace weft::cloth {

ClothSpec default_cloth_spec() {
  // 4×4 cotton plain weave, ≈2.2 mm square and ≈0.7 mm thick, ≈770 fibres: ≈0.56 M active
  // voxels of 10 µm, generated and voxelized in a few seconds on 2 cores (weft validate runs on
  // it in CI).
  ClothSpec spec;
  spec.pattern = "plain";
  spec.warp_count = 4;
  spec.weft_count = 4;
  spec.warp_yarn = yarn_preset("cotton");
  spec.weft_yarn = yarn_preset("cotton");
  spec.voxel_size = 0.01;
  spec.seed = 1;
  return resolve(spec);
}

ClothSpec load_cloth_spec(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail("{}: no such file", path.string());
  // A folder opens and reads as nothing: it would be said to be "an empty file".
  if (std::filesystem::is_directory(path, ec)) fail("{}: not a regular file (a folder)", path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("{}: cannot open", path.string());
  std::ostringstream text;
  text << in.rdbuf();
  // A wrong kind of file (the .vdb beside cloth.json, a .bcc) is named, not fed to the JSON
  // parser, whose message ("parse error ... last read: ' B'") says nothing useful.
  const std::string_view head = std::string_view(text.view()).substr(0, 512);
  if (!looks_like_json(head))
    fail("{}: not a cloth JSON (looks like {}); a cloth JSON is the cloth.json weft gen writes", path.string(),
         file_kind(head));
  ClothSpec spec = cloth_spec_from_json(text.str(), path.string());
  // Curves named in a config sit beside it, as a scene's files do (docs/cloth.md
  // "Patterns"); kept absolute, so cloth.json written from it names them wherever it is saved.
  if (!spec.input.empty()) spec.input = resolve_beside(spec.input, path.parent_path());
  return spec;
}

FiberSet generate_fibers(const ClothSpec& spec, const CurveSet& centerlines, ProgressSink& progress) {
  std::vector<YarnJob> jobs(centerlines.curves.size());
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    jobs[i].centerline = &centerlines.curves[i];
    jobs[i].params = centerlines.direction[i] == 1 ? &spec.weft_yarn : &spec.warp_yarn;
    jobs[i].yarn_id = static_cast<std::int32_t>(i);
  }
  return build_yarns(jobs, spec.seed, progress);
}

volume::Provenance cloth_provenance(const ClothBuild& build) {
  // σ per unit concentration, fibre-volume weighted over every fibre (docs/validate.md, "σ: physical by default"):
  // each fibre of radius r and length ℓ has volume π r² ℓ and, seen across the beam, projected
  // area 2 r ℓ, so σ = Σ 2 r ℓ / Σ π r² ℓ (= 2/(π r) when all fibres share one radius).
  const auto& f = build.fibers;
  double projected = 0.0;
  double volume = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    double len = 0.0;
    for (std::uint64_t p = f.offsets[i] + 1; p < f.offsets[i + 1]; ++p) {
      const auto& a = f.points[p - 1];
      const auto& b = f.points[p];
      len += std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    }
    projected += 2.0 * f.radius[i] * len;
    volume += std::numbers::pi * f.radius[i] * f.radius[i] * len;
  }
  volume::Provenance p;
  p.units = "mm";
  p.value_kind = "concentration";
  if (volume > 0.0) {
    p.sigma = projected / volume;
    p.fiber_radius = 2.0 / (std::numbers::pi * *p.sigma);
    p.sigma_rule = "sum(2 r l)/sum(pi r^2 l) over the fibres: opaque fibres across the beam (2/(pi r_f))";
  }
  // Yarn diameter: 2 × envelope radius, averaged over the centrelines (each uses its preset).
  double diameter = 0.0;
  for (int d : build.centerlines.direction)
    diameter += 2.0 * yarn_envelope_radius(d == 1 ? build.spec.weft_yarn : build.spec.warp_yarn);
  if (!build.centerlines.direction.empty())
    p.yarn_diameter = diameter / static_cast<double>(build.centerlines.direction.size());
  p.source = "weft gen";
  return p;
}

std::vector<std::string> cloth_warnings(const ClothBuild& build, FrontEnd asker) {
  std::vector<std::string> out;
  const ClothSpec& spec = build.spec;
  // The yarns the centrelines use: knit and imported cloths only the warp's.
  bool warp = false;
  bool weft = false;
  for (int d : build.centerlines.direction) (d == 1 ? weft : warp) = true;
  // One line when both directions would say the same.
  const bool one = !weft || !warp ||
                   (spec.warp_yarn.loop_density == spec.weft_yarn.loop_density &&
                    loop_coverage(spec.warp_yarn) == loop_coverage(spec.weft_yarn));
  const auto saturated = [&](const YarnParams& y, const char* which) {
    const double c = loop_coverage(y);
    if (!(c > 1.0)) return;
    const Spelling option{"--set loop_density", "loop_density"};
    out.push_back(fmt::format(
        "{}: {}={:.3g} puts {:.3g} loop flyaways over each fibre point (loop_density x migration_period / "
        "fiber_count > 1): the fibres are pulled out nearly everywhere, so more loops change the cloth little and "
        "cost time (loops reshape regular fibres and add none)",
        which, option.in(asker), y.loop_density, c));
  };
  if (one) {
    saturated(warp ? spec.warp_yarn : spec.weft_yarn, warp && weft ? "yarns" : "yarn");
  } else {
    saturated(spec.warp_yarn, "warp yarn");
    saturated(spec.weft_yarn, "weft yarn");
  }
  if (build.report.overlap_fraction > kOverlapWarning) {
    const Spelling options{"--spacing, --crimp or fiber_min_spacing",
                           "warp_spacing=, weft_spacing=, crimp= or fiber_min_spacing"};
    out.push_back(fmt::format(
        "{:.1f} % of the fibre volume overlaps other fibres and was clamped at C = 1 (over {:.0f} %): the grid holds "
        "that much less fibre than the fibres, which pass through each other (check {})",
        100.0 * build.report.overlap_fraction, 100.0 * kOverlapWarning, options.in(asker)));
  }
  return out;
}

ClothBuild build_cloth(const ClothSpec& input, ProgressSink& progress, bool spread_over_ranks, FrontEnd asker,
                       ClothStage upto) {
  ClothBuild build;
  validate(input);  // before resolve: an automatic spacing or crimp is named as such
  build.spec = resolve(input);
  if (upto == ClothStage::spec) return build;
  const auto t0 = std::chrono::steady_clock::now();
  const std::uint64_t budget = memory_budget_bytes("max_memory_mb", build.spec.max_memory_mb);
  // The budget covers the stages built: without a grid, the fibres and what makes them.
  const auto what_is_built = [upto](ClothEstimate e) { return upto == ClothStage::grid ? e : without_grid(e); };
  // Woven and knit specs are checked before their centrelines are made (a huge --yarns would
  // spend minutes and gigabytes on those alone); imports on the curves they read.
  if (build.spec.pattern != "import" && upto != ClothStage::centerlines)
    check_budget(what_is_built(estimate_cloth(build.spec)), budget, asker, "cloth", build.spec.config);
  build.centerlines = cloth_centerlines(build.spec);
  if (build.centerlines.curves.empty()) fail("cloth: the pattern produced no yarns");
  if (upto == ClothStage::centerlines) return build;
  build.estimate = what_is_built(estimate_cloth(build.spec, build.centerlines));
  check_budget(build.estimate, budget, asker,
               build.spec.pattern == "import"
                   ? fmt::format("cloth of {} at input_scale {}", build.spec.input, build.spec.input_scale)
                   : "cloth",
               build.spec.config);
  build.fibers = generate_fibers(build.spec, build.centerlines, progress);
  const double generate_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (upto == ClothStage::fibers) {
    build.report.fiber_count = build.fibers.size();
    build.report.generate_seconds = generate_seconds;
    return build;
  }
  VoxelizeOptions options;
  options.voxel_size = build.spec.voxel_size;
  options.samples_per_voxel = build.spec.samples_per_voxel;
  options.max_memory_bytes = budget;
  options.spread = spread_over_ranks;
  options.asker = asker;
  build.grid = voxelize(build.fibers, options, build.report, progress);
  // Fibres whose C per voxel rounds to 0 in float (a fiber_radius of 1e-300 mm) leave no voxel:
  // said with the radius here, not later as an empty cloth.vdb. Under mpirun only rank 0 holds
  // the grid (voxelize's `spread`).
  if (build.grid.active_voxel_count() == 0 && (!spread_over_ranks || dist::is_root())) {
    const Spelling radius{"--set fiber_radius", "fiber_radius"};
    const Spelling voxel{"--voxel-size", "voxel_size="};
    fail(
        "cloth: the grid is empty: fibres of radius {} mm ({}) hold {:.3g} mm^3 in all, which leaves no voxel of "
        "{} mm a fibre volume fraction above 0 in float: raise {} or lower {}",
        std::max(build.spec.warp_yarn.fiber_radius, build.spec.weft_yarn.fiber_radius), radius.in(asker),
        build.report.fiber_volume, build.spec.voxel_size, radius.in(asker), voxel.in(asker));
  }
  build.report.generate_seconds = generate_seconds;
  // Provenance (no timings: the same spec must give the same file).
  build.grid.set_metadata("generator", cloth_spec_json(build.spec));
  build.grid.set_metadata("seed", std::to_string(build.spec.seed));
  build.grid.set_metadata("fiber_volume_mm3", fmt::format("{}", build.report.fiber_volume));
  build.grid.set_metadata("volume_relative_error", fmt::format("{}", build.report.relative_error));
  build.grid.set_metadata("overlap_fraction", fmt::format("{}", build.report.overlap_fraction));
  volume::write_provenance(build.grid, cloth_provenance(build));
  record_voxelized_lattice(build.grid);  // what fibers_of_grid checks a grid against
  return build;
}

}  // namespace weft::cloth
