// The render-study matrix (render_matrix.h; docs/render.md §6e).
#include "weft/study/render_matrix.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "data_gen/cloth/cloth.h"
#include "weft/core/atomic_file.h"
#include "weft/core/distinct.h"
#include "weft/core/error.h"
#include "weft/core/number_name.h"
#include "weft/dist/distributed.h"
#include "weft/dist/unit_store.h"
#include "weft/render/cloth_scene.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/study/albedo_fit.h"
#include "weft/study/render_study_report.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::study {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using Factors = std::vector<std::pair<int, double>>;

cloth::ClothSpec cloth_spec(const MatrixSpec& spec, const std::string& pattern) {
  cloth::ClothSpec c = cloth::default_cloth_spec();
  c.pattern = pattern;
  c.warp_count = spec.yarns;
  c.weft_count = spec.yarns;
  c.voxel_size = spec.voxel_size;
  c.seed = spec.cloth_seed;
  return cloth::resolve(c);
}

/// The cloth's grid under work_dir/cloths/, named by its pattern (alias resolved) and a hash of
/// its resolved generator spec, so a changed generator or spec makes a new file and an existing
/// one is the same cloth.
fs::path cloth_file(const MatrixSpec& spec, const std::string& pattern) {
  const cloth::ClothSpec c = cloth_spec(spec, pattern);
  const std::string text = cloth::cloth_spec_json(c);
  return fs::absolute(spec.study.work_dir / "cloths" /
                      fmt::format("{}_{:016x}.vdb", c.pattern, std::hash<std::string>{}(text)));
}

/// The metadata key under which the matrix records a cloth's resolved generator spec in its grid:
/// the file's name hashes the spec, the key says what the file holds.
constexpr const char* kClothSpecKey = "weft:matrix_cloth_spec";

/// Generates the cloth of `pattern` into its file, with its spec recorded (kClothSpecKey).
void make_cloth(const MatrixSpec& spec, const std::string& pattern, const fs::path& file, ProgressSink& progress) {
  const cloth::ClothSpec c = cloth_spec(spec, pattern);
  volume::Grid grid = cloth::build_cloth(c, progress).grid;
  grid.set_metadata(kClothSpecKey, cloth::cloth_spec_json(c));
  grid.save(file);
}

/// A grid already under a cloth's name is taken only if it records that cloth's spec: a file
/// copied or left there by hand would otherwise be rendered under the pattern's name.
void require_matrix_cloth(const MatrixSpec& spec, const std::string& pattern, const fs::path& file,
                          const volume::Grid& grid) {
  const auto meta = grid.metadata();
  const auto it = meta.find(kClothSpecKey);
  if (it == meta.end() || it->second != cloth::cloth_spec_json(cloth_spec(spec, pattern)))
    fail("render matrix: '{}' is not the {} cloth its name says ({}); remove it and run again", file.string(),
         cloth::canonical_pattern(pattern),
         it == meta.end() ? "it records no generator spec" : "it records another generator spec");
}

render::SceneDesc case_scene(const MatrixSpec& spec, const MatrixCase& c) {
  render::ClothView view;
  view.lighting = c.lighting;
  view.tilt_degrees = c.tilt;
  view.width = spec.width;
  view.height = spec.height;
  return render::cloth_scene(cloth_file(spec, spec.cloths[c.cloth]), view);
}

/// The study's candidate JSON (study_candidate_json) with the memory of MatrixMemory, without
/// the scene path: it names the run's folder, and a case's bytes must not depend on where it ran.
json candidate_json(const MatrixCandidate& mc) {
  json j = study_candidate_json(mc.study);
  j.erase("scene");
  j["memory_bytes"] = mc.memory.values;
  j["memory_tree_bytes"] = mc.memory.tree;
  j["memory_channels"] = mc.memory.channels;
  return j;
}

MatrixCandidate candidate_from(const json& j) {
  MatrixCandidate mc;
  mc.study = study_candidate_from_json(j);
  mc.memory = {j.at("memory_bytes").get<std::uint64_t>(), j.at("memory_tree_bytes").get<std::uint64_t>(),
               j.at("memory_channels").get<int>()};
  return mc;
}

// A case crosses ranks and the --resume store as MessagePack of matrix_case_json: doubles
// round-trip exactly, so rank 0 writes the digits a one-process run writes (as the corpus,
// corpus.cpp).
dist::Bytes encode(const MatrixCaseResult& r) { return json::to_msgpack(matrix_case_json(r)); }

MatrixCaseResult decode(const MatrixCase& c, const dist::Bytes& b) {
  const json j = json::from_msgpack(b);
  MatrixCaseResult r;
  r.c = c;
  r.width = j.at("width").get<int>();
  r.height = j.at("height").get<int>();
  r.reference_spp = j.at("reference_spp").get<int>();
  r.reference_mean = j.at("reference_mean").get<double>();
  r.cloth_pixels = j.at("cloth_pixels").get<int>();
  r.cloth_mean = j.at("cloth_mean").get<double>();
  r.reference_seconds = j.at("reference_seconds").get<double>();
  for (const auto& f : j.at("albedo_factors"))
    r.albedo_factors.emplace_back(f.at("factor").get<int>(), f.at("albedo_multiplier").get<double>());
  for (const auto& cj : j.at("candidates")) r.candidates.push_back(candidate_from(cj));
  for (const auto& fj : j.at("resolution_floors")) r.resolution_floors.push_back(resolution_floor_from_json(fj));
  r.notes = j.at("notes").get<std::vector<std::string>>();
  return r;
}

/// One case: the study of its scene on this rank, its files in its folder, the memory of each
/// representation from the files the study wrote. Its renders move `cases` by kMatrixCaseUnits as
/// they go (ProgressShare), and a stop requested there (Cancelled) leaves the case unfinished:
/// no files of its report, nothing stored.
MatrixCaseResult run_case(const MatrixSpec& spec, const MatrixCase& c, const Factors& factors, ProgressTask& cases) {
  const dist::RankLocal local;  // the study's renders stay on this rank
  const fs::path dir = matrix_case_dir(spec, c);
  // The case's folder is whole or as it was: the study guards its own folder (study/), this the
  // report files written after it, up to the case's result, which the store keeps next. A stop
  // between the two leaves a complete case that --resume renders again.
  FolderRollback case_files(dir);
  StudySpec s = spec.study;
  s.work_dir = dir / "study";
  s.files_root = spec.study.work_dir;  // the cases' scenes name ../../../cloths/ relative: the run moves whole
  s.log = nullptr;
  s.albedo_factors = factors;
  ProgressShare share(cases, kMatrixCaseUnits, std::string(kStudyRendersStage));
  const StudyResult r = run_study(case_scene(spec, c), s, share);
  share.finish();
  (void)write_study_files(r, dir / "reference.exr", s.work_dir, 1.0);
  MatrixCaseResult out;
  out.c = c;
  out.width = r.reference.width;
  out.height = r.reference.height;
  out.reference_spp = r.reference.spp;
  out.reference_mean = r.reference_mean;
  out.cloth_pixels = r.cloth_pixels;
  out.cloth_mean = r.cloth_mean;
  out.reference_seconds = r.reference_seconds;
  out.albedo_factors = factors;
  out.resolution_floors = r.resolution_floors;
  out.notes = r.notes;
  for (const StudyCandidate& sc : r.candidates) {
    MatrixCandidate mc;
    mc.study = sc;
    mc.study.image = {};
    mc.study.error_map = {};
    mc.memory = {sc.memory_bytes, sc.memory_tree_bytes, sc.memory_channels};
    out.candidates.push_back(std::move(mc));
  }
  case_files.keep();
  return out;
}

/// Per cloth, the albedo factors fitted on its first lighting × first view (docs/render.md §6d
/// (b)): one unit per cloth, gathered on rank 0 and broadcast, so every rank takes the same numbers.
std::vector<Factors> fit_factors(const MatrixSpec& spec, const std::vector<MatrixCase>& cases, dist::UnitStore* store,
                                 ProgressSink& progress) {
  const std::vector<std::string> patterns = matrix_patterns(spec);
  std::vector<Factors> out(spec.cloths.size());
  std::vector<const MatrixCase*> fitted(spec.cloths.size(), nullptr);
  for (const auto& c : cases)
    if (c.fitted_on) fitted[c.cloth] = &c;
  std::optional<dist::UnitStore> fits;
  if (store != nullptr)
    fits.emplace(store->folder().parent_path() / "fits.units", matrix_key(spec), store->resume(), store->front_end());
  dist::UnitsOptions how;
  how.batch = 1;
  how.store = fits ? &*fits : nullptr;
  how.name = [&](std::size_t u) { return fmt::format("albedo fit of cloth {} ({})", u, patterns[u]); };
  const auto bytes = dist::run_units(
      spec.cloths.size(),
      [&](std::size_t u) {
        const dist::RankLocal local;
        StudySpec s = spec.study;
        s.work_dir = spec.study.work_dir / "fits" / patterns[u];
        s.log = nullptr;
        json j = json::array();
        for (const auto& [f, a] : fit_albedo_factors(case_scene(spec, *fitted[u]), s, progress)) j.push_back({f, a});
        return json::to_msgpack(j);
      },
      how);
  // Gathered on rank 0, sent to every rank (no file: the ranks need not share a filesystem).
  dist::Bytes all;
  if (dist::is_root()) {
    json j = json::array();
    for (const auto& b : bytes) j.push_back(json::from_msgpack(b));
    all = json::to_msgpack(j);
  }
  const json j = json::from_msgpack(dist::root_bytes(std::move(all)));
  for (std::size_t u = 0; u < out.size(); ++u)
    for (const auto& f : j.at(u)) out[u].emplace_back(f.at(0).get<int>(), f.at(1).get<double>());
  return out;
}

}  // namespace

json matrix_case_json(const MatrixCaseResult& r) {
  json cands = json::array();
  for (const auto& c : r.candidates) cands.push_back(candidate_json(c));
  json factors = json::array();
  for (const auto& [f, a] : r.albedo_factors) factors.push_back({{"factor", f}, {"albedo_multiplier", a}});
  json floors = json::array();
  for (const auto& f : r.resolution_floors) floors.push_back(resolution_floor_json(f));
  return {{"case", r.c.name},
          {"cloth", r.c.pattern},
          {"lighting", render::cloth_lighting_name(r.c.lighting)},
          {"tilt", r.c.tilt},
          {"fitted_on", r.c.fitted_on},
          {"width", r.width},
          {"height", r.height},
          {"reference_spp", r.reference_spp},
          {"reference_mean", r.reference_mean},
          {"cloth_pixels", r.cloth_pixels},
          {"cloth_mean", r.cloth_mean},
          {"reference_seconds", r.reference_seconds},
          {"albedo_factors", factors},
          {"resolution_floors", floors},
          {"notes", r.notes},
          {"candidates", cands}};
}

MatrixSpec default_matrix_spec(bool quick) {
  MatrixSpec spec;
  spec.study = default_study_spec(false);
  spec.study.factors = {2, 4, 8};
  spec.study.memory_rules = {transmittance::kDefaultMemoryRule, transmittance::MemoryRule::segment};
  spec.study.spp = quick ? 8 : 64;
  spec.study.reference_spp = quick ? 128 : 1024;
  spec.study.albedo_fitted = true;  // per cloth, on its first set-up (fit_factors)
  if (quick) {
    spec.yarns = 2;
    spec.voxel_size = 0.02;
    spec.width = 32;
    spec.height = 24;
  }
  return spec;
}

void check_matrix_spec(const MatrixSpec& spec, FrontEnd front) {
  if (spec.cloths.empty()) fail("render matrix: no cloths");
  for (const auto& p : spec.cloths) cloth::validate(cloth_spec(spec, p));  // an unknown pattern is refused here
  // A repeated cloth, light set-up or view would render the same case twice under one folder
  // (docs/robustness.md "Options that would do nothing"). A cloth is its pattern: an alias and
  // its pattern (twill, twill22) are one cloth.
  const std::vector<std::string> patterns = matrix_patterns(spec);
  require_distinct(
      "render matrix", patterns,
      [&](std::size_t i) {
        std::set<std::string> spelt;  // how the user wrote this pattern
        for (std::size_t k = 0; k < patterns.size(); ++k)
          if (patterns[k] == patterns[i]) spelt.insert(spec.cloths[k]);
        if (spelt == std::set<std::string>{patterns[i]}) return fmt::format("cloth '{}'", patterns[i]);
        return fmt::format("cloth '{}' (as '{}')", patterns[i], fmt::join(spelt, "', '"));
      },
      [](const std::string& p) { return p; });
  if (spec.lightings.empty()) fail("render matrix: no light set-ups");
  require_distinct(
      "render matrix", spec.lightings,
      [&](std::size_t i) { return fmt::format("light set-up '{}'", render::cloth_lighting_name(spec.lightings[i])); },
      [](render::ClothLighting l) { return l; });
  if (spec.tilts.empty()) fail("render matrix: no views");
  for (const double t : spec.tilts) render::check_cloth_tilt("render matrix: view", t);
  require_distinct(
      "render matrix", spec.tilts,
      [&](std::size_t i) { return fmt::format("view at tilt {} degrees", matrix_tilt_name(spec.tilts[i])); },
      [](double t) { return t; });  // no NaN: check_cloth_tilt refused it
  if (spec.width < kMinMatrixFilm || spec.height < kMinMatrixFilm || spec.width > kMaxMatrixFilm ||
      spec.height > kMaxMatrixFilm)
    fail("render matrix: film {}x{}: each side must be in [{}, {}] px", spec.width, spec.height, kMinMatrixFilm,
         kMaxMatrixFilm);
  if (spec.yarns < 1 || spec.yarns > kMaxMatrixYarns)
    fail("render matrix: yarns must be in [1, {}], got {}", kMaxMatrixYarns, spec.yarns);
  if (!(spec.voxel_size > 0.0) || !std::isfinite(spec.voxel_size))
    fail("render matrix: voxel size must be > 0, got {}", spec.voxel_size);
  if (spec.study.spp <= 0)
    fail("render matrix: the cases render at a fixed spp (so a case's numbers do not depend on where it ran)");
  // The matrix always fits albedo factors per cloth, so its albedo-corrected candidates exist
  // for --study-components even where the spec was not made by default_matrix_spec.
  StudySpec study = spec.study;
  study.albedo_fitted = true;
  check_study_spec(study, front);
  // Every case's renders (study_pixel_samples: the reference, the background, the candidates and
  // their components), before a cloth is generated.
  const double cases = static_cast<double>(spec.cloths.size() * spec.lightings.size() * spec.tilts.size());
  render::require_pixel_samples(cases * study_pixel_samples(study, spec.width, spec.height), "render matrix",
                                front == FrontEnd::python ? "spp=, reference_spp=, film=, components= or the cases"
                                                          : "--study-spp, --reference-spp, --study-film, "
                                                            "--study-components or the cases");
}

std::vector<std::string> matrix_patterns(const MatrixSpec& spec) {
  std::vector<std::string> out;
  out.reserve(spec.cloths.size());
  for (const auto& c : spec.cloths) out.push_back(cloth::canonical_pattern(c));
  return out;
}

std::string matrix_tilt_name(double tilt) { return number_name(tilt); }

std::vector<MatrixCase> matrix_cases(const MatrixSpec& spec) {
  const std::vector<std::string> patterns = matrix_patterns(spec);
  std::vector<MatrixCase> out;
  for (std::size_t k = 0; k < spec.cloths.size(); ++k) {
    for (const auto lighting : spec.lightings) {
      for (const double tilt : spec.tilts) {
        MatrixCase c;
        c.cloth = k;
        c.pattern = patterns[k];
        c.lighting = lighting;
        c.tilt = tilt;
        c.name = fmt::format("{}-{}-{}deg", patterns[k], render::cloth_lighting_name(lighting), matrix_tilt_name(tilt));
        c.fitted_on = lighting == spec.lightings.front() && tilt == spec.tilts.front();
        out.push_back(std::move(c));
      }
    }
  }
  return out;
}

fs::path matrix_case_dir(const MatrixSpec& spec, const MatrixCase& c) { return spec.study.work_dir / "cases" / c.name; }

std::string matrix_key(const MatrixSpec& spec) {
  json lightings = json::array();
  for (const auto l : spec.lightings) lightings.push_back(render::cloth_lighting_name(l));
  json rules = json::array();
  for (const auto r : spec.study.memory_rules) rules.push_back(std::string(transmittance::memory_rule_name(r)));
  const json key = {{"weft", "render --study (matrix)"},
                    {"cloths", matrix_patterns(spec)},
                    {"yarns", spec.yarns},
                    {"voxel_size", spec.voxel_size},
                    {"cloth_seed", spec.cloth_seed},
                    {"lightings", lightings},
                    {"tilts", spec.tilts},
                    {"film", {spec.width, spec.height}},
                    {"factors", spec.study.factors},
                    {"memory_rules", rules},
                    {"spp", spec.study.spp},
                    {"reference_spp", spec.study.reference_spp},
                    {"seed", spec.study.seed},
                    {"scale", spec.study.scale},
                    {"albedo_fit", true},
                    {"components", spec.study.components},
                    // What a stored case holds (the study's candidate JSON, the resolution floors,
                    // 7: its warnings) and what its coarse grids are (6: blocks anchored to the
                    // cloth, docs/render.md §5); bumped when either changes.
                    {"case_format", 7}};
  return key.dump(2) + "\n";
}

std::vector<MatrixCaseResult> run_matrix(const MatrixSpec& spec, ProgressSink& progress, dist::UnitStore* store) {
  check_matrix_spec(spec);
  const std::vector<MatrixCase> cases = matrix_cases(spec);
  // A refused run leaves nothing (docs/render.md §6c "Factors"): the folders and cloths this run
  // makes are removed if it fails before its cloths pass the factor check; after that they stay
  // for the next run. An unwritable folder is refused by its name before any cloth is made.
  if (dist::is_root()) check_writable_folder(spec.study.work_dir);
  FolderRollback made(spec.study.work_dir / "cloths", dist::is_root());
  (void)dist::root_decides(true);

  // 1. The cloths, one unit each (a grid already there is the same cloth: its name hashes its spec).
  const std::vector<std::string> patterns = matrix_patterns(spec);
  dist::UnitsOptions gen;
  gen.batch = 1;  // one cloth at a time per rank: a voxelization's memory, not two
  gen.name = [&](std::size_t u) { return fmt::format("cloth {} ({})", u, patterns[u]); };
  (void)dist::run_units(
      spec.cloths.size(),
      [&](std::size_t u) {
        const dist::RankLocal local;
        const fs::path file = cloth_file(spec, spec.cloths[u]);
        if (!fs::exists(file)) make_cloth(spec, spec.cloths[u], file, progress);
        return dist::Bytes{};
      },
      gen);

  // A factor too coarse for a cloth is refused before any fit or render. Every rank loads every
  // cloth, so the refusal waits for all of them (a collective) before the root removes the cloths.
  std::exception_ptr refused;
  try {
    for (const auto& pattern : spec.cloths) {
      const fs::path file = cloth_file(spec, pattern);
      const volume::Grid grid = volume::Grid::load(file);
      require_matrix_cloth(spec, pattern, file, grid);
      try {
        check_factors_for_grid(spec.study.factors, grid);
      } catch (const Error& e) {
        // The grid's own name ("density") would not say which of the cloths is too small.
        fail("render matrix: cloth '{}': {}", cloth::canonical_pattern(pattern), e.what());
      }
    }
  } catch (const Error&) {
    refused = std::current_exception();
  }
  (void)dist::root_decides(refused == nullptr);
  if (refused) std::rethrow_exception(refused);
  made.keep();

  // 2. The albedo factors per cloth, fitted on one set-up.
  const std::vector<Factors> factors = fit_factors(spec, cases, store, progress);

  // 3. The cases, each on one rank. One at a time per rank, so a case's CPU time per sample (the
  // process's clock around its renders) is its own.
  ProgressTask task(progress, kMatrixCasesStage, cases.size() * kMatrixCaseUnits);
  dist::UnitsOptions how;
  how.batch = 1;
  how.progress = &task;
  how.unit_weight = kMatrixCaseUnits;  // run_case steps its own case as it renders
  how.store = store;
  // A stored case is its numbers; its images, grids and scenes are in its folder. If that folder
  // was removed, or never finished its report, the case is rendered again rather than reported
  // without them (run_case's rollback keeps a folder whole, so its report file says it is).
  how.resumable = [&](std::size_t u) { return fs::exists(matrix_case_dir(spec, cases[u]) / "reference.study.json"); };
  how.name = [&](std::size_t u) { return fmt::format("study case {} ({})", u, cases[u].name); };
  const std::vector<dist::Bytes> units = dist::run_units(
      cases.size(), [&](std::size_t u) { return encode(run_case(spec, cases[u], factors[cases[u].cloth], task)); },
      how);
  std::vector<MatrixCaseResult> out;
  if (!dist::is_root()) return out;
  for (std::size_t u = 0; u < units.size(); ++u) out.push_back(decode(cases[u], units[u]));
  return out;
}

}  // namespace weft::study
