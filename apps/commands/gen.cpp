// `weft gen`: procedural cloth (Zhao et al. 2016 yarns in a weave or knit, or around imported
// curves) voxelized to a grid of fibre volume fraction.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "command.h"
#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/voxelize.h"
#include "interrupt.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/core/names.h"
#include "weft/core/number_name.h"
#include "weft/core/parse_number.h"
#include "weft/curves/curve_io.h"
#include "weft/dist/distributed.h"
#include "weft/render/cloth_scene.h"
#include "weft/viz/vtk_files.h"
#include "weft/volume/grid.h"
#include "written_files.h"

namespace weft::app {
namespace {
namespace fs = std::filesystem;
using cloth::ClothSpec;

struct GenOptions {
  std::string config;
  std::string pattern;
  std::string yarns;
  double spacing = 0.0;
  double warp_spacing = 0.0;
  double weft_spacing = 0.0;
  double crimp = 0.0;
  std::string yarn;
  std::string warp_yarn;
  std::string weft_yarn;
  std::vector<std::string> set;
  std::string input;
  double input_scale = 1.0;
  double voxel_size = 0.01;
  int samples_per_voxel = 4;
  std::uint64_t seed = 1;
  std::string max_memory;
  std::string out = "cloth";
  bool fibers_bcc = false;
  std::string write = "grid,fibers,yarns,config";
};

// What `--write` may name, with the file each one is.
struct Output {
  const char* name;
  const char* file;
  const char* what;
};
constexpr std::array<Output, 5> kOutputs{{{"grid", "cloth.vdb", "grid"},
                                          {"fibers", "fibers.vtp", "fibres"},
                                          {"yarns", "yarns.bcc", "yarn centrelines"},
                                          {"config", "cloth.json", "parameters"},
                                          {"fibers-bcc", "fibers.bcc", "fibres as BCC"}}};

// "grid,fibers" → the set of outputs, or the problem of the first name that is none ("" when
// every name is known).
std::pair<std::set<std::string>, std::string> read_outputs(const std::string& list) {
  std::set<std::string> out;
  std::string known;
  for (const auto& o : kOutputs) known += (known.empty() ? "" : ", ") + std::string(o.name);
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string name = list.substr(start, comma - start);
    if (name == "all") {
      for (const auto& o : kOutputs) out.insert(o.name);
    } else if (std::none_of(kOutputs.begin(), kOutputs.end(), [&](const Output& o) { return name == o.name; })) {
      return {{},
              name.empty() ? fmt::format("an empty output name in '{}' (known: {}, all)", list, known)
                           : fmt::format("unknown output '{}' (known: {}, all)", name, known)};
    } else {
      out.insert(name);
    }
    start = comma + 1;
  }
  return {out, ""};
}

// --write checked while the command line is parsed: a bad name is a usage error (exit 2).
const CLI::Validator output_list([](std::string& text) { return read_outputs(text).second; }, "LIST", "outputs");

// "512M", "2G", "1.5GiB", "1000000" (bytes) → MiB.
double parse_memory_mb(const std::string& text) {
  // The number by std::from_chars, as weft::parse_number (locale-free; 1e-320 is a number), then a unit.
  const char* first = text.data() + (text.starts_with('+') ? 1 : 0);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(first, text.data() + text.size(), value);
  if (ec != std::errc() || end == first) usage_fail("--max-memory: '{}' is not a size (e.g. 512M, 4G)", text);
  std::string unit(end, text.data() + text.size());
  if (!unit.empty() && (unit.back() == 'B' || unit.back() == 'b')) unit.pop_back();
  if (unit.size() == 2 && (unit[1] == 'i' || unit[1] == 'I')) unit.pop_back();
  double bytes = value;
  if (unit.empty()) {
  } else if (unit == "K" || unit == "k") {
    bytes *= 1024.0;
  } else if (unit == "M" || unit == "m") {
    bytes *= 1024.0 * 1024.0;
  } else if (unit == "G" || unit == "g") {
    bytes *= 1024.0 * 1024.0 * 1024.0;
  } else if (unit == "T" || unit == "t") {
    bytes *= 1024.0 * 1024.0 * 1024.0 * 1024.0;
  } else {
    usage_fail("--max-memory: unknown unit in '{}' (use K, M, G or T)", text);
  }
  if (!(bytes > 0.0) || !std::isfinite(bytes)) usage_fail("--max-memory: must be finite and > 0, got '{}'", text);
  // Less than a byte is a byte (as memory_budget_bytes rounds up): 1e-320 bytes in MiB would
  // underflow to 0, the spec's "default".
  return std::max(bytes, 1.0) / (1024.0 * 1024.0);
}

void set_yarn_field(cloth::YarnParams& yarn, const std::string& key, const std::string& value,
                    const std::string& where) {
  for (const auto& f : cloth::yarn_fields()) {
    if (key != f.name) continue;
    const std::optional<double> parsed = parse_option_number(value);
    if (!parsed) usage_fail("{}: '{}' is {}", where, value, number_problem(value));
    const double v = *parsed;
    if (f.integer) {
      if (v != std::floor(v)) usage_fail("{}: '{}' is not an integer", where, value);
      if (std::abs(v) > 1e9) usage_fail("{}: must be in [-1e9, 1e9] (an integer field), got {}", where, value);
      yarn.*(f.whole) = static_cast<int>(v);
    } else {
      yarn.*(f.real) = v;
    }
    return;
  }
  std::vector<std::string> names;
  for (const auto& f : cloth::yarn_fields()) names.emplace_back(f.name);
  const std::string near = closest_name(key, names, std::max<std::size_t>(2, key.size() / 3));
  usage_fail("{}: unknown yarn parameter '{}'{} (see weft gen --help)", where, key,
             near.empty() ? std::string() : fmt::format("; did you mean '{}'?", near));
}

std::string yarn_parameter_help() {
  std::string text =
      "Yarn parameters (Zhao, Luan & Bala 2016), set with --set NAME=VALUE (both directions) or\n"
      "--set warp.NAME=VALUE / weft.NAME=VALUE; lengths in mm. Cotton defaults:\n";
  const cloth::YarnParams cotton = cloth::yarn_preset("cotton");
  for (const auto& f : cloth::yarn_fields()) {
    const std::string value = f.integer ? fmt::format("{}", cotton.*(f.whole)) : fmt::format("{}", cotton.*(f.real));
    text += fmt::format("  {:<22} [{}] {} (cotton: {})\n", f.name, f.unit, f.doc, value);
  }
  std::string presets;
  for (const auto& n : cloth::yarn_preset_names()) presets += (presets.empty() ? "" : ", ") + n;
  text += "Yarn presets: " + presets +
          ".\nIn a --config yarn, \"preset\" fills the fields it does not give and given fields\n"
          "override it; cloth.json records the changes (\"wool (modified: fiber_count)\"), and a yarn\n"
          "giving every field, all another preset's, under a preset's name is refused (docs/cloth.md,\n"
          "Presets and explicit fields).\n";
  text +=
      "Outputs in --out, chosen with --write (default grid,fibers,yarns,config): grid = cloth.vdb (grid\n"
      "'density' of fibre volume fraction C, provenance as metadata), fibers = fibers.vtp (fibres with\n"
      "yarn/ply/fiber/kind ids, zlib-compressed, float32 points), yarns = yarns.bcc (centrelines),\n"
      "config = cloth.json (every parameter; weft gen --config cloth.json rebuilds the same grid),\n"
      "fibers-bcc = fibers.bcc (every fibre as a BCC polyline, for weft render). A run builds only\n"
      "what its outputs need (config alone: no yarns; yarns: no fibres; no grid: no voxelization).\n"
      "The summary lists each file written with its size. The memory a run needs is estimated from the centrelines\n"
      "before any fibre is made and a run over --max-memory, or over 1e12 steps of work (about an hour\n"
      "of one core), is refused with the estimate, naming a flyaway parameter when one is most of it.\n"
      "With the grid, scene.json (weft render <out>/scene.json renders the grid as a medium) is written\n"
      "too.";
  return text;
}

ClothSpec make_spec(CLI::App& sub, const GenOptions& o) {
  const auto given = [&](const char* name) { return sub.get_option(name)->count() > 0; };
  ClothSpec spec = o.config.empty() ? cloth::default_cloth_spec() : cloth::load_cloth_spec(o.config);
  spec.config = o.config;
  if (o.config.empty()) {
    // Automatic spacings follow the yarns chosen on the command line.
    spec.warp_spacing = spec.weft_spacing = spec.crimp = 0.0;
  }
  if (given("--pattern")) {
    spec.pattern = o.pattern;
    if (!given("--spacing") && !given("--crimp")) spec.warp_spacing = spec.weft_spacing = spec.crimp = 0.0;
  }
  if (given("--yarns")) {
    // Two whole numbers around an x, each read whole (sscanf's %d wrapped 4294967297 to 1).
    const std::string_view text = o.yarns;
    const std::size_t x = text.find_first_of("xX");
    const auto count = [](std::string_view t) -> std::optional<long long> {
      long long v = 0;
      const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), v);
      if (error != std::errc() || end != t.data() + t.size()) return std::nullopt;
      return v;
    };
    const std::optional<long long> a = x == std::string_view::npos ? std::nullopt : count(text.substr(0, x));
    const std::optional<long long> b = x == std::string_view::npos ? std::nullopt : count(text.substr(x + 1));
    if (!a || !b || *a < 1 || *b < 1)
      usage_fail("--yarns: expected WARPxWEFT with positive counts (e.g. 8x8), got '{}'", o.yarns);
    if (*a > cloth::kMaxYarnCount || *b > cloth::kMaxYarnCount)
      usage_fail("--yarns: counts must be in [1, {}], got '{}'", cloth::kMaxYarnCount, o.yarns);
    spec.warp_count = static_cast<int>(*a);
    spec.weft_count = static_cast<int>(*b);
  }
  if (given("--yarn")) spec.warp_yarn = spec.weft_yarn = as_usage([&] { return cloth::yarn_preset(o.yarn); });
  if (given("--warp-yarn")) spec.warp_yarn = as_usage([&] { return cloth::yarn_preset(o.warp_yarn); });
  if (given("--weft-yarn")) spec.weft_yarn = as_usage([&] { return cloth::yarn_preset(o.weft_yarn); });
  for (const auto& kv : o.set) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) usage_fail("--set: expected NAME=VALUE, got '{}'", kv);
    std::string key = kv.substr(0, eq);
    const std::string value = kv.substr(eq + 1);
    const std::string where = "--set " + kv;
    if (key.rfind("warp.", 0) == 0) {
      set_yarn_field(spec.warp_yarn, key.substr(5), value, where);
    } else if (key.rfind("weft.", 0) == 0) {
      set_yarn_field(spec.weft_yarn, key.substr(5), value, where);
    } else {
      set_yarn_field(spec.warp_yarn, key, value, where);
      set_yarn_field(spec.weft_yarn, key, value, where);
    }
  }
  if (given("--spacing")) spec.warp_spacing = spec.weft_spacing = o.spacing;
  if (given("--warp-spacing")) spec.warp_spacing = o.warp_spacing;
  if (given("--weft-spacing")) spec.weft_spacing = o.weft_spacing;
  if (given("--crimp")) spec.crimp = o.crimp;
  if (given("--input")) {
    spec.input = fs::absolute(o.input).lexically_normal().string();
    if (!given("--pattern")) spec.pattern = "import";
  }
  // Conflicts are errors, not silently dropped options: a pattern other than import ignores the
  // input curves, and an import ignores the pattern's yarn counts, spacings and crimp.
  const bool import = spec.pattern == "import";
  if (!import && !spec.input.empty()) {
    if (given("--input"))
      usage_fail("--input {} and --pattern {} conflict: a woven or knit pattern ignores input curves (give one)",
                 o.input, spec.pattern);
    if (given("--pattern")) {
      usage_fail(
          "--pattern {} conflicts with the input curves {} of --config {} (a woven or knit pattern ignores "
          "them; edit the config's \"input\" out to switch)",
          spec.pattern, spec.input, o.config);
    }
    // Neither option was given: the config contradicts itself, a problem of the file (exit 1).
    fail(
        "{}: \"input\": {} conflicts with \"pattern\": \"{}\" (a woven or knit pattern ignores input curves: "
        "set \"pattern\": \"import\" or remove \"input\")",
        o.config, spec.input, spec.pattern);
  }
  if (import) {
    for (const char* name : {"--yarns", "--spacing", "--warp-spacing", "--weft-spacing", "--crimp"}) {
      if (given(name))
        usage_fail("{} conflicts with imported curves ({}): it only shapes woven and knit patterns", name,
                   spec.input.empty() ? std::string("--pattern import") : spec.input);
    }
  }
  if (given("--input-scale")) spec.input_scale = o.input_scale;
  if (given("--voxel-size")) spec.voxel_size = o.voxel_size;
  if (given("--samples-per-voxel")) spec.samples_per_voxel = o.samples_per_voxel;
  if (given("--seed")) spec.seed = o.seed;
  if (given("--max-memory")) spec.max_memory_mb = parse_memory_mb(o.max_memory);
  // Every parameter is checked before anything runs or is written. A --config file was checked
  // when loaded (exit 1), so what fails here comes from the command line: a usage error (exit 2).
  // Checked before resolving, so that an automatic (0) spacing or crimp is known as such and the
  // yarn fields behind it are named (cloth::check_cloth_extent).
  as_usage([&] { cloth::validate(spec); });
  return cloth::resolve(spec);
}

// The fibres as VTK polylines, taking their arrays (the caller's last use of them): a copy of
// the points would be the largest buffer of the run (24 bytes a point, more than the grid).
viz::PolylineSet fibers_as_polylines(cloth::FiberSet&& fibers) {
  viz::PolylineSet lines;
  lines.points = std::move(fibers.points);
  lines.offsets = std::move(fibers.offsets);
  lines.cell_ints["yarn"] = std::move(fibers.yarn);
  lines.cell_ints["ply"] = std::move(fibers.ply);
  lines.cell_ints["fiber"] = std::move(fibers.fiber);
  auto& kind = lines.cell_ints["kind"];
  for (auto k : fibers.kind) kind.push_back(static_cast<std::int32_t>(k));
  lines.cell_scalars["radius"] = std::move(fibers.radius);
  lines.float_points = true;  // ~0.1 nm at the scale of a swatch: plenty for viewing, half the file
  fibers = cloth::FiberSet{};
  return lines;
}

const Registrar kGen{Command{
    "gen", "Generate procedural cloth (yarns -> fibres) and voxelize it to fibre volume fraction", 10,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<GenOptions>();
      std::string patterns;
      for (const auto& n : cloth::pattern_names()) patterns += (patterns.empty() ? "" : ", ") + n;
      std::string presets;
      for (const auto& n : cloth::yarn_preset_names()) presets += (presets.empty() ? "" : ", ") + n;
      sub.add_option("--config", o->config, "cloth.json of an earlier run: rebuild it (other options override it)")
          ->check(file_name);
      sub.add_option("--pattern", o->pattern,
                     "Pattern: " + patterns + "; twill = twill22, satin = satin5, knit = stockinette (default plain)");
      sub.add_option("--yarns", o->yarns, "Yarn counts WARPxWEFT (knit: COURSESxWALES), default 4x4");
      sub.add_option("--spacing", o->spacing,
                     "mm between neighbouring yarns, both directions (0 = from the yarn size)");
      sub.add_option("--warp-spacing", o->warp_spacing, "mm between warp yarns (knit: courses); 0 = automatic");
      sub.add_option("--weft-spacing", o->weft_spacing, "mm between weft yarns (knit: wales); 0 = automatic");
      sub.add_option("--crimp", o->crimp,
                     "mm, half the over/under height of the weave (knit: loop depth); 0 = automatic");
      sub.add_option("--yarn", o->yarn, "Yarn preset of both directions: " + presets + " (default cotton)");
      sub.add_option("--warp-yarn", o->warp_yarn, "Yarn preset of the warp (and of knit/imported yarns)");
      sub.add_option("--weft-yarn", o->weft_yarn, "Yarn preset of the weft");
      sub.add_option("--set", o->set,
                     "Yarn parameter NAME=VALUE, warp.NAME=VALUE or weft.NAME=VALUE (repeatable; list below)");
      sub.add_option("--input", o->input,
                     "Yarn centrelines to build fibres around: .bcc (PL or C0) or .obj ('l' polylines)")
          ->check(file_name);
      sub.add_option("--input-scale", o->input_scale, "Factor from the input file's units to mm")
          ->check(positive)
          ->capture_default_str();
      sub.add_option("--voxel-size", o->voxel_size,
                     fmt::format("Voxel edge in mm: >= {} (OpenVDB's smallest), below the cloth's longest side",
                                 bound_text(volume::min_voxel_size(), BoundSide::at_least)))
          ->check(positive)
          ->capture_default_str();
      sub.add_option("--samples-per-voxel", o->samples_per_voxel,
                     "Voxelizer quadrature points per voxel edge (volume is conserved for any value)")
          ->capture_default_str();
      sub.add_option("--seed", o->seed, "Run seed: same seed, same cloth, whatever --threads")->capture_default_str();
      sub.add_option("--max-memory", o->max_memory,
                     "Refuse runs whose memory, estimated before generating, exceeds this (e.g. 512M, 4G); "
                     "default half the RAM");
      sub.add_option("--out", o->out, "Output folder (created if missing)")->capture_default_str();
      sub.add_option("--write", o->write,
                     "Outputs, comma separated: grid, fibers, yarns, config, fibers-bcc, or all (list below)")
          ->check(output_list)
          ->capture_default_str();
      sub.add_flag("--fibers-bcc", o->fibers_bcc, "Also write the fibres as fibers.bcc (same as adding fibers-bcc)");
      sub.footer(yarn_parameter_help());
      CLI::App* app = &sub;
      return [o, app](const Context& ctx) -> int {
        std::set<std::string> outputs = read_outputs(o->write).first;  // checked by output_list
        if (o->fibers_bcc) outputs.insert("fibers-bcc");
        const ClothSpec spec = make_spec(*app, *o);
        // Only the stages the outputs need: cloth.json alone resolves the spec, yarns.bcc adds the
        // centrelines, the fibre files the fibres, cloth.vdb (and scene.json) the grid.
        const cloth::ClothStage upto = outputs.count("grid") != 0 ? cloth::ClothStage::grid
                                       : outputs.count("fibers") != 0 || outputs.count("fibers-bcc") != 0
                                           ? cloth::ClothStage::fibers
                                       : outputs.count("yarns") != 0 ? cloth::ClothStage::centerlines
                                                                     : cloth::ClothStage::spec;
        // Under mpirun the voxelizer's leaves are spread over the ranks; rank 0 gets the grid and
        // writes (docs/scale-out.md).
        cloth::ClothBuild build =
            cloth::build_cloth(spec, ctx.progress, /*spread_over_ranks=*/true, FrontEnd::cli, upto);
        if (!dist::is_root()) return 0;
        // The summary's figures first: the grid and the fibres are released as soon as their
        // files are written, so that the run's peak is the voxelizer's, not the outputs'.
        const auto& r = build.report;
        // Loops reshape regular fibres and add none: said as how many and on how many fibres.
        const cloth::FiberSet& f = build.fibers;
        const std::string made =
            upto >= cloth::ClothStage::fibers
                ? fmt::format(
                      "{} cloth, {} yarns, {} fibres ({:.1f} mm of fibre) with {} hairs and {} loop flyaways on {} of "
                      "them, seed {}",
                      build.spec.pattern, build.centerlines.curves.size(), r.fiber_count, f.length(),
                      f.count(cloth::FiberKind::hair), f.loops, f.count(cloth::FiberKind::loop), build.spec.seed)
            : upto == cloth::ClothStage::centerlines
                ? fmt::format("{} cloth, {} yarns (centrelines only: no fibres or grid were asked for), seed {}",
                              build.spec.pattern, build.centerlines.curves.size(), build.spec.seed)
                : fmt::format("{} cloth, seed {} (its parameters only: no yarns, fibres or grid were asked for)",
                              build.spec.pattern, build.spec.seed);
        const std::vector<std::string> warnings =
            upto >= cloth::ClothStage::fibers ? cloth::cloth_warnings(build) : std::vector<std::string>();
        const std::string memory =
            upto == cloth::ClothStage::grid
                ? fmt::format("memory: grid {} (OpenVDB), fibres {}; estimated before generating: {}",
                              format_bytes(build.grid.memory_bytes()),
                              format_bytes(build.fibers.points.size() * sizeof(cloth::Point3)),
                              cloth::describe(build.estimate))
                : fmt::format("memory: fibres {}; estimated before generating: {}",
                              format_bytes(build.fibers.points.size() * sizeof(cloth::Point3)),
                              cloth::describe(build.estimate));
        const fs::path out(o->out);
        // The outputs appear together or not at all: a Ctrl-C (or a failed write) between two
        // files removes what this run added (docs/robustness.md "Output folders of failed runs").
        FolderRollback written(out);
        WrittenFiles files;
        const fs::path scene = out / "scene.json";
        for (const auto& output : kOutputs) {
          if (outputs.count(output.name) == 0) continue;
          stop_if_interrupted();  // no progress is reported while files are written
          const fs::path path = out / output.file;
          const std::string name = output.name;
          if (name == "grid") {
            build.grid.save(path);
            // A scene that renders the grid as is: `weft render <out>/scene.json` (docs/render.md).
            write_text_atomically(scene, render::cloth_scene_json(build.grid, "cloth.vdb"));
          } else if (name == "fibers") {
            // fibers-bcc (after this in kOutputs) still needs the fibres; otherwise this is their last use.
            if (outputs.count("fibers-bcc") != 0) {
              cloth::FiberSet copy = build.fibers;
              viz::write_vtp(fibers_as_polylines(std::move(copy)), path);
            } else {
              viz::write_vtp(fibers_as_polylines(std::move(build.fibers)), path);
            }
          } else if (name == "yarns") {
            curves::write_bcc(path, build.centerlines.curves, "weft yarn centrelines (mm)");
          } else if (name == "config") {
            write_text_atomically(path, cloth::cloth_spec_json(build.spec));
          } else {
            curves::write_bcc(path, cloth::fiber_curves(build.fibers), "weft fibres (mm)");
          }
          files.add(path, output.what);
          if (name == "grid") build.grid = volume::Grid();  // written: its tree is not needed any more
        }
        if (outputs.count("grid") != 0) files.add(scene, "render scene");
        stop_if_interrupted();
        written.keep();
        ctx.say(made);
        if (upto == cloth::ClothStage::grid) {
          ctx.say(
              fmt::format("voxel size {} mm: {} active voxels; fibre volume {:.6g} mm^3, grid volume {:.6g} mm^3 "
                          "(relative error {:.2e}, overlap clamped {:.3f} %)",
                          build.spec.voxel_size, r.active_voxels, r.fiber_volume, r.grid_volume, r.relative_error,
                          100.0 * r.overlap_fraction));
          ctx.say(fmt::format(
              "generated in {:.2f} s, voxelized in {:.2f} s ({:.0f} fibres/s, {:.3g} voxels/s); {} rank(s) x "
              "{} thread(s)",
              r.generate_seconds, r.voxelize_seconds, r.fiber_count / std::max(r.voxelize_seconds, 1e-9),
              r.active_voxels / std::max(r.voxelize_seconds, 1e-9), ctx.ranks(), ctx.threads()));
        } else if (upto == cloth::ClothStage::fibers) {
          ctx.say(fmt::format("generated in {:.2f} s (no grid: cloth.vdb was not asked for); {} rank(s) x {} thread(s)",
                              r.generate_seconds, ctx.ranks(), ctx.threads()));
        }
        if (upto >= cloth::ClothStage::fibers) ctx.say(memory);
        files.say(ctx);
        for (const std::string& w : warnings) ctx.warn(w);
        return 0;
      };
    },
    /*distributed=*/true}};

}  // namespace
}  // namespace weft::app
