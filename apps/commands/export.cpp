// `weft export`: a grid plus ready scenes for Mitsuba 3 (.xml + .vol) and pbrt-v4 (.pbrt + .nvdb).
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "command.h"
#include "grid_input.h"
#include "interrupt.h"
#include "usage.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/core/parse_number.h"
#include "weft/volume/dense.h"
#include "weft/volume/renderer_export.h"
#include "written_files.h"

namespace weft::app {
namespace {
namespace fs = std::filesystem;

struct ExportOptions {
  GridInputOptions input;
  std::string out = "export";
  std::string formats = "mitsuba,pbrt";
  std::string albedo = "0.8";
  double g = 0.0;
  int width = 256;
  int height = 192;
  int spp = 64;
  double max_memory_mb = 0.0;
};

// A comma list's items must all be there: getline drops a trailing empty one ("pbrt," read as
// "pbrt", "0.5," as a grey albedo), so an empty item anywhere is refused, as gen's --write does.
void require_items(const char* option, const std::string& text) {
  if (text.empty() || text.front() == ',' || text.back() == ',' || text.find(",,") != std::string::npos)
    usage_fail("{}: an empty item in '{}'", option, text);
}

std::array<double, 3> parse_albedo(const std::string& text) {
  require_items("--albedo", text);
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const std::optional<double> x = parse_option_number(item);
    if (!x) fail("--albedo: '{}' is {}", item, number_problem(item));
    v.push_back(*x + 0.0);  // -0 is 0: the scenes write "0", not "-0"
  }
  if (v.size() == 1) return {v[0], v[0], v[0]};
  if (v.size() != 3) fail("--albedo: expected A or R,G,B, got '{}'", text);
  return {v[0], v[1], v[2]};
}

int run(const ExportOptions& o, const Context& ctx) {
  // Every option is checked before anything is read (exit 2), every refusal before the first file.
  bool mitsuba = false;
  bool pbrt = false;
  require_items("--format", o.formats);
  std::stringstream ss(o.formats);
  std::string f;
  while (std::getline(ss, f, ',')) {
    if ((f == "mitsuba" && mitsuba) || (f == "pbrt" && pbrt)) usage_fail("--format: '{}' is given twice", f);
    if (f == "mitsuba") {
      mitsuba = true;
    } else if (f == "pbrt") {
      pbrt = true;
    } else {
      usage_fail("--format: unknown format '{}' (mitsuba, pbrt)", f);
    }
  }
  if (!mitsuba && !pbrt) usage_fail("--format: give mitsuba, pbrt or both");
  // The budget bounds the dense cloth.vol; pbrt's NanoVDB grid is the size of the grid itself.
  if (o.max_memory_mb > 0.0 && !mitsuba)
    usage_fail("--max-memory-mb needs --format mitsuba (the dense cloth.vol it bounds)");
  check_grid_input(o.input);
  volume::ExportMedium medium;
  medium.albedo = as_usage([&] { return parse_albedo(o.albedo); });
  medium.g = o.g;
  volume::ExportView view;
  view.width = o.width;
  view.height = o.height;
  view.spp = o.spp;
  medium.sigma = o.input.sigma_given() ? o.input.sigma : 1.0;
  as_usage([&] { volume::validate(medium, view); });

  // σ the same way as validate, measure and fit: --sigma, else the grid's provenance
  // (weft:sigma_per_concentration), --values extinction for μ grids; never a silent σ = 1.
  const LoadedGrid loaded = load_grid_input(o.input);
  const volume::Grid& grid = loaded.grid;
  const volume::IndexBox box = grid.active_bbox();
  medium.sigma = loaded.sigma.sigma;
  medium.extinction = o.input.extinction();
  medium.units = loaded.provenance.units;
  volume::validate(medium, view);  // σ from the grid's provenance
  const volume::WorldBox world = volume::world_box(grid, box);
  const std::string grid_label = fmt::format("{}: grid '{}'", o.input.grid, grid.name());
  if (mitsuba) volume::check_float_resolution(grid, box, volume::ExportFormat::mitsuba, grid_label);
  if (pbrt) volume::check_float_resolution(grid, box, volume::ExportFormat::pbrt, grid_label);
  const std::uint64_t budget = memory_budget_bytes("--max-memory-mb", o.max_memory_mb);
  const fs::path out(o.out);
  const fs::path vol_path = out / "mitsuba" / "cloth.vol";
  const fs::path nvdb_path = out / "pbrt" / "cloth.nvdb";
  if (mitsuba) volume::check_mitsuba_vol(box, vol_path, budget);
  const std::string xml = mitsuba ? volume::mitsuba_scene_xml(world, "cloth.vol", medium, view) : std::string();
  const std::string pbrt_text = pbrt ? volume::pbrt_scene(world, "cloth.nvdb", medium, view) : std::string();

  // Everything is computed before the first folder is made, reporting progress, so a Ctrl-C
  // stops it there (docs/architecture.md "Progress and cancellation") and leaves nothing.
  // NanoVDB first: its conversion's temporary copy of the grid is gone before the dense array is made.
  std::optional<volume::NanoVdbGrid> nvdb;
  if (pbrt) nvdb.emplace(grid, nvdb_path, ctx.progress);
  std::optional<volume::MitsubaVolume> vol;
  if (mitsuba) vol = volume::mitsuba_volume(grid, box, vol_path, budget, ctx.progress);

  // The files appear together or not at all: a Ctrl-C (or a failed write) between two of them
  // removes what this run added (docs/robustness.md "Output folders of failed runs").
  FolderRollback written(out);
  WrittenFiles files;
  if (mitsuba) {
    stop_if_interrupted();  // no progress is reported while files are written
    ensure_directory(vol_path.parent_path());
    volume::write_mitsuba_vol(*vol, vol_path);
    vol.reset();
    files.add(vol_path, "Mitsuba 3 dense grid");
    write_text_atomically(out / "mitsuba" / "cloth.xml", xml);
    files.add(out / "mitsuba" / "cloth.xml", "Mitsuba 3 scene");
  }
  if (pbrt) {
    stop_if_interrupted();
    ensure_directory(nvdb_path.parent_path());
    nvdb->write();
    files.add(nvdb_path, "pbrt-v4 NanoVDB grid");
    write_text_atomically(out / "pbrt" / "cloth.pbrt", pbrt_text);
    // pbrt-v4's medium is not weft's (docs/export.md): said where the file is listed.
    files.add(out / "pbrt" / "cloth.pbrt", "pbrt-v4 scene; " + volume::pbrt_interpolation_note());
  }
  stop_if_interrupted();
  written.keep();
  files.say(ctx);
  ctx.say(fmt::format("sigma = {:.6g} per unit {} ({}), albedo {}, g {}", medium.sigma,
                      o.input.extinction() ? "extinction value" : "concentration", loaded.sigma.source, o.albedo, o.g));
  return 0;
}

const Registrar kExport{Command{
    "export", "Export a grid and a ready scene for Mitsuba 3 (.xml + .vol) and pbrt-v4 (.pbrt + .nvdb)", 65,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<ExportOptions>();
      add_grid_input(sub, o->input, true);
      sub.add_option("--out", o->out, "Output folder (mitsuba/ and pbrt/ inside)")->capture_default_str();
      sub.add_option("--format", o->formats, "mitsuba, pbrt or mitsuba,pbrt")->capture_default_str();
      sub.add_option("--albedo", o->albedo, "Single-scattering albedo A or R,G,B in [0, 1]")->capture_default_str();
      sub.add_option("--g", o->g, "Henyey-Greenstein asymmetry in (-1, 1)")->capture_default_str();
      sub.add_option("--width", o->width, "Image width of the scenes")->capture_default_str();
      sub.add_option("--height", o->height, "Image height of the scenes")->capture_default_str();
      sub.add_option("--spp", o->spp, "Samples per pixel of the scenes")->capture_default_str();
      // A memory limit, as gen's --max-memory and Python's max_memory_mb=: finite and > 0.
      sub.add_option("--max-memory-mb", o->max_memory_mb,
                     "Refuse a dense .vol above this many MiB, > 0 (default: half the RAM)")
          ->check(positive);
      sub.footer(
          "Writes OUT/mitsuba/cloth.xml + cloth.vol (Mitsuba 3 heterogeneous medium, gridvolume with nearest\n"
          "filtering, scale = sigma) and OUT/pbrt/cloth.pbrt + cloth.nvdb (pbrt-v4 nanovdb medium, grid 'density',\n"
          "which pbrt-v4 interpolates trilinearly: a smoother medium than weft's piecewise-constant voxels).\n"
          "Lengths stay in the grid's units (mm for weft gen). See docs/export.md.");
      return [o](const Context& ctx) { return run(*o, ctx); };
    }}};

}  // namespace
}  // namespace weft::app
