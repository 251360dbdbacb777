#include "data_gen/cloth/cloth.h"

#include <chrono>
#include <fstream>
#include <sstream>

#include "data_gen/cloth/pattern.h"
#include "data_gen/cloth/voxelize.h"
#include "data_gen/cloth/yarn.h"
#include "weft/core/error.h"
#include "weft/core/file_kind.h"
#include "weft/core/parallel.h"

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
  return cloth_spec_from_json(text.str(), path.string());
}

FiberSet generate_fibers(const ClothSpec& spec, const CurveSet& centerlines, ProgressSink& progress) {
  const std::size_t n = centerlines.curves.size();
  std::vector<FiberSet> per_yarn(n);
  {
    ProgressTask task(progress, "generating fibres", n);
    parallel_units(n, [&](std::size_t i) {
      const YarnParams& yarn = centerlines.direction[i] == 1 ? spec.weft_yarn : spec.warp_yarn;
      per_yarn[i] = yarn_fibers(centerlines.curves[i], yarn, spec.seed, static_cast<std::int32_t>(i));
      task.step();
    });
  }
  FiberSet all;
  for (const auto& f : per_yarn) all.append(f);
  return all;
}

ClothBuild build_cloth(const ClothSpec& input, ProgressSink& progress) {
  ClothBuild build;
  build.spec = resolve(input);
  validate(build.spec);
  const auto t0 = std::chrono::steady_clock::now();
  build.centerlines = cloth_centerlines(build.spec);
  if (build.centerlines.curves.empty()) fail("cloth: the pattern produced no yarns");
  build.fibers = generate_fibers(build.spec, build.centerlines, progress);
  const double generate_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  VoxelizeOptions options;
  options.voxel_size = build.spec.voxel_size;
  options.samples_per_voxel = build.spec.samples_per_voxel;
  options.max_memory_bytes = static_cast<std::uint64_t>(build.spec.max_memory_mb * 1024.0 * 1024.0);
  build.grid = voxelize(build.fibers, options, build.report, progress);
  build.report.generate_seconds = generate_seconds;
  // Provenance (no timings: the same spec must give the same file).
  build.grid.set_metadata("generator", cloth_spec_json(build.spec));
  build.grid.set_metadata("seed", std::to_string(build.spec.seed));
  build.grid.set_metadata("fiber_volume_mm3", fmt::format("{}", build.report.fiber_volume));
  build.grid.set_metadata("volume_relative_error", fmt::format("{}", build.report.relative_error));
  build.grid.set_metadata("overlap_fraction", fmt::format("{}", build.report.overlap_fraction));
  return build;
}

}  // namespace weft::cloth
