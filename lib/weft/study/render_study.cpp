// Accuracy against time in images (study.h; docs/render.md §6c).
#include "weft/study/render_study.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "weft/core/atomic_file.h"
#include "weft/core/distinct.h"
#include "weft/core/error.h"
#include "weft/dist/distributed.h"
#include "weft/fit/gamma_moments.h"
#include "weft/fit/local_fields.h"
#include "weft/fit/report.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/fit/window_stats.h"
#include "weft/render/convergence.h"
#include "weft/render/medium.h"
#include "weft/render/render.h"
#include "weft/study/albedo_fit.h"
#include "weft/study/bias_estimate.h"
#include "weft/study/render_study_report.h"
#include "weft/study/representation_memory.h"
#include "weft/study/study_target.h"
#include "weft/volume/downsample.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/provenance.h"
#include "weft/volume/shadowed_downsample.h"

namespace weft::study {
// The study composes the renderer's scenes, images and statistics throughout.
using namespace weft::render;  // NOLINT(google-build-using-namespace)
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::uint64_t kSeedStep = kStudySeedStep;

double mean_square(const Image& a, const Image& b) {
  const double e = rmse(a, b);
  return e * e;
}

double image_mean(const Image& im) {
  double s = 0.0;
  for (const float v : im.rgb) s += v;
  return im.rgb.empty() ? 0.0 : s / static_cast<double>(im.rgb.size());
}

/// |a − b| averaged over the three channels, as grey (the error map of the contact sheet).
Image abs_difference(const Image& a, const Image& b) {
  Image d = a;
  for (std::size_t p = 0; p + 2 < d.rgb.size(); p += 3) {
    float e = 0.0F;
    for (std::size_t c = 0; c < 3; ++c) e += std::abs(a.rgb[p + c] - b.rgb[p + c]);
    for (std::size_t c = 0; c < 3; ++c) d.rgb[p + c] = e / 3.0F;
  }
  d.variance.clear();
  return d;
}

/// `dir` (or a file) absolute and normal, its symbolic links resolved where it exists: one spelling
/// for the run's folder, a scene file's folder and the files they name, so one is found inside the other.
fs::path resolved_folder(const fs::path& dir) {
  std::error_code ec;
  const fs::path r = fs::weakly_canonical(fs::absolute(dir), ec);
  return ec ? fs::absolute(dir).lexically_normal() : r;
}

/// Every string of the scene `j` that is an absolute path inside `root` becomes relative to `dir`
/// (the folder of the scene file being written, where parse_scene resolves it back): the run's
/// folder can be moved whole. Paths elsewhere stay as they are.
void name_files_relative(json& j, const fs::path& root, const fs::path& dir) {
  if (j.is_object() || j.is_array()) {
    for (auto& v : j) name_files_relative(v, root, dir);
    return;
  }
  if (!j.is_string()) return;
  const fs::path p(j.get<std::string>());
  if (!p.is_absolute()) return;
  const fs::path normal = resolved_folder(p);  // a file, spelt as the folders are
  const auto [r, q] = std::mismatch(root.begin(), root.end(), normal.begin(), normal.end());
  if (r != root.end() && !(std::next(r) == root.end() && r->empty())) return;  // not inside root
  j = normal.lexically_relative(dir).string();
}

/// The spp of the scene without the cloth's box, which the cloth's mask compares the reference with.
int background_spp(const StudySpec& spec) { return std::max(16, spec.reference_spp / 4); }

/// Samples per pixel of every render a study makes at a fixed spp (the reference and its
/// components, the background, images A and B of each named candidate and theirs); with a time
/// budget, of the renders whose spp is known (the candidates' end with the budget). One count for
/// the work limit before the study and its progress during it.
std::uint64_t study_spp_sum(const StudySpec& spec, const std::vector<std::string>& candidates) {
  std::uint64_t sum = static_cast<std::uint64_t>(spec.reference_spp) * (spec.components.empty() ? 1 : 3) +
                      static_cast<std::uint64_t>(background_spp(spec));
  if (spec.spp <= 0) return sum;
  for (const std::string& name : candidates)
    sum += static_cast<std::uint64_t>(spec.spp) * (splits_components(spec.components, name) ? 6 : 2);
  return sum;
}

void say(const StudySpec& spec, const std::string& line) {
  if (spec.log) spec.log(line);
}

/// The study's renders as one stage kStudyRendersStage in pixel samples (render_study.h), when
/// their samples are known beforehand (a fixed spp); with a time budget each render is a stage.
class RenderProgress {
 public:
  RenderProgress(ProgressSink& progress, std::uint64_t total_samples) : progress_(progress) {
    if (total_samples > 0) task_.emplace(progress, kStudyRendersStage, total_samples);
  }
  /// fn(sink) for renders of `samples` pixel samples in all.
  template <typename Fn>
  auto run(std::uint64_t samples, Fn&& fn) {
    if (!task_) return fn(progress_);
    ProgressShare share(*task_, samples);
    auto out = fn(static_cast<ProgressSink&>(share));
    share.finish();
    return out;
  }

 private:
  ProgressSink& progress_;
  std::optional<ProgressTask> task_;
};

}  // namespace

StudySpec default_study_spec(bool quick) {
  StudySpec spec;
  if (quick) {
    spec.seconds = 1.0;
    spec.reference_spp = 256;
  }
  return spec;
}

std::vector<std::string> candidate_families(const StudySpec& spec) {
  std::vector<std::string> out{"fine", "exponential"};
  for (const auto rule : spec.memory_rules)  // the default rule's candidates are local-gamma-Nx
    out.push_back(rule == transmittance::kDefaultMemoryRule
                      ? "local-gamma"
                      : "local-gamma-" + std::string(transmittance::memory_rule_name(rule)));
  out.emplace_back("shadow-corrected");
  out.emplace_back("shadow-directional");
  if (!spec.albedo_factors.empty() || spec.albedo_fitted) out.emplace_back("albedo-corrected");
  out.emplace_back("slab-gamma");
  return out;
}

void check_study_spec(const StudySpec& spec, FrontEnd front) {
  if (spec.factors.empty()) fail("study: no coarsening factors");
  std::set<int> seen;
  for (const int f : spec.factors) {
    if (f < 2 || f > 4096) fail("study: coarsening factor {} is not in [2, 4096]", f);
    if (!seen.insert(f).second) fail("study: coarsening factor {} given twice", f);
  }
  // The limits of the CLI's options, here so that every front end refuses the same values before
  // anything is rendered.
  if (spec.spp < 0) fail("study: spp must be >= 0 (0 = time budget), got {}", spec.spp);
  if (spec.spp > kMaxStudySpp) fail("study: spp must be at most {}, got {}", kMaxStudySpp, spec.spp);
  if (spec.spp == 0 && !(spec.seconds >= kMinStudySeconds && spec.seconds <= kMaxStudySeconds))
    fail("study: time budget must be in [{:g}, {:g}] seconds, got {}", kMinStudySeconds, kMaxStudySeconds,
         spec.seconds);
  if (spec.max_spp < 1) fail("study: max spp must be >= 1, got {}", spec.max_spp);
  if (spec.reference_spp < 1 || spec.reference_spp > render::kMaxSpp)
    fail("study: reference spp must be in [1, {}], got {}", render::kMaxSpp, spec.reference_spp);
  if (spec.work_dir.empty()) fail("study: no folder for the candidates' files");
  // A rule given twice would render its candidates twice under one name.
  require_distinct(
      "study", spec.memory_rules,
      [&](std::size_t i) {
        return fmt::format("memory rule '{}'", transmittance::memory_rule_name(spec.memory_rules[i]));
      },
      [](transmittance::MemoryRule r) { return r; });
  // A family given twice is the list's mistake, as a repeated rule is (every other study list
  // refuses its repeats).
  require_distinct(
      "study", spec.components, [&](std::size_t i) { return fmt::format("component family '{}'", spec.components[i]); },
      [](const std::string& f) { return f; });
  // A family that names no candidate would split nothing silently (render_components.h).
  const std::vector<std::string> families = candidate_families(spec);
  std::vector<std::string> rules;
  for (const auto r : spec.memory_rules) rules.emplace_back(transmittance::memory_rule_name(r));
  for (const auto& f : spec.components) {
    if (f == "all" || std::find(families.begin(), families.end(), f) != families.end()) continue;
    // local-gamma-RULE of a rule the study does not render: say which rules it renders, and how
    // to add one, rather than the list of families.
    const std::string prefix = "local-gamma-";
    const std::optional<transmittance::MemoryRule> rule =
        f == "local-gamma"      ? std::optional(transmittance::kDefaultMemoryRule)
        : f.starts_with(prefix) ? transmittance::parse_memory_rule(f.substr(prefix.size()))
                                : std::nullopt;
    if (rule && std::find(spec.memory_rules.begin(), spec.memory_rules.end(), *rule) == spec.memory_rules.end())
      fail("study: components of '{}': {} is not one of the study's memory rules ({}); add it to {}", f,
           transmittance::memory_rule_name(*rule), fmt::join(rules, ", "),
           Spelling{"--study-memory", "memory="}.in(front));
    if (f == "albedo-corrected")
      fail("study: components of 'albedo-corrected': the study has no albedo-corrected candidate; add them with {}",
           Spelling{"--study-albedo", "albedo="}.in(front));
    if (rule)  // local-gamma-optical-depth: the default rule's candidates are local-gamma-Nx
      fail("study: components of '{}': the {} rule's candidates are local-gamma-Nx: give 'local-gamma'", f,
           transmittance::memory_rule_name(*rule));
    fail("study: components of '{}': no such candidate family ({}, all)", f, fmt::join(families, ", "));
  }
  std::set<int> fitted;
  for (const auto& [f, k] : spec.albedo_factors) {
    if (!seen.contains(f)) fail("study: albedo factor for {}x, which is not a coarsening factor of the study", f);
    if (!fitted.insert(f).second) fail("study: albedo factor for {}x given twice", f);
    if (!(std::isfinite(k) && k > 0.0)) fail("study: albedo factor k for {}x must be finite and > 0, got {}", f, k);
  }
}

void check_factors_for_grid(const std::vector<int>& factors, const volume::Grid& fine) {
  for (const int f : factors) {
    if (const auto whole = fit::whole_box_block(f, fine))
      fail(
          "study: coarsening factor {}: {}, so every coarse candidate would be one homogeneous box; use factors "
          "below {}",
          f, whole->text, whole->below);
  }
}

std::vector<int> factors_for_grid(const StudySpec& spec, const volume::Grid& fine) {
  if (spec.factors_given) {
    check_factors_for_grid(spec.factors, fine);
    return spec.factors;
  }
  const volume::IndexBox box = fine.active_bbox();
  if (box.empty()) return spec.factors;
  const auto extent = box.extent();
  const std::int64_t largest = *std::max_element(extent.begin(), extent.end());
  std::vector<int> kept;
  std::vector<int> dropped;
  for (const int f : spec.factors) (f < largest ? kept : dropped).push_back(f);
  if (kept.empty()) check_factors_for_grid(spec.factors, fine);  // says why, and what would do
  for (const auto& [f, k] : spec.albedo_factors) {
    if (std::find(kept.begin(), kept.end(), f) == kept.end())
      fail(
          "study: albedo factor {}:{:g} names a coarsening factor the grid is too small for (factors below {} "
          "only)",
          f, k, largest);
  }
  if (!dropped.empty() && spec.log)
    spec.log(fmt::format(
        "default coarsening factor{} {} left out: one coarse voxel would hold the whole active box "
        "of grid '{}' ({}x{}x{} voxels)",
        dropped.size() > 1 ? "s" : "", fmt::join(dropped, ", "), fine.name(), extent[0], extent[1], extent[2]));
  return kept;
}

void check_study_scene(const SceneDesc& scene, const StudySpec& spec) {
  const Target target = find_target(scene);
  // Nothing that emits: every image is black, the cloth's mask empty, and the study would blame
  // the camera or the reference's noise after rendering it (a plain render warns instead). A light
  // of intensity 0 (or an image scaled by 0) emits nothing either; an image's own pixels are not
  // read here.
  const bool emitter = std::any_of(scene.shapes.begin(), scene.shapes.end(),
                                   [](const ShapeDesc& s) { return (s.emission > 0.0).any(); }) ||
                       std::any_of(scene.lights.begin(), scene.lights.end(), [](const LightDesc& l) {
                         return l.scale > 0.0 && (!l.image.empty() || (l.intensity > 0.0).any());
                       });
  if (!emitter)
    fail(
        "study: the scene has no light that emits (nothing in \"lights\" with a power above 0 and no shape with "
        "\"emission\"): every image would be black and the cloth invisible; add a light");
  // A k past albedo_k_max clamps every channel at 1: it renders as k_max does, so it is a typo or
  // a factor meant for a darker cloth. The slack lets a k printed with 6 digits (as --study-albedo
  // fit prints them, rounded by up to 5e-6 relative) pass when the fit ended at k_max.
  const Rgb& albedo = scene.media.at(target.medium).albedo;
  const double k_max = albedo_k_max(albedo);
  // An albedo of 0 in every channel stays 0 for any k: nothing is clamped, so nothing to refuse.
  const bool any_scattering = (albedo > 0.0).any();
  for (const auto& [f, k] : spec.albedo_factors) {
    if (any_scattering && k > k_max * (1.0 + 1e-5))
      fail(
          "study: albedo factor {}:{:g} takes the albedo ({:g}, {:g}, {:g}) of medium '{}' above 1 in every channel "
          "that is not 0 (each is clamped at 1, so it renders as k = {:.6g} does); use k <= {:.6g}",
          f, k, albedo[0], albedo[1], albedo[2], target.medium, k_max, k_max);
  }
  if (!spec.components.empty()) check_component_scene(scene);
  // Its renders, before anything is made.
  render::require_pixel_samples(study_pixel_samples(spec, scene.camera.width, scene.camera.height), "study",
                                "--study-spp, --reference-spp, --study-components or the camera's film");
  // The box against the grid: loaded here, so that every front end refuses a box that cuts the
  // cloth before it says what the study will cost, let alone renders.
  const MediumDesc& fine_desc = scene.media.at(target.medium);
  check_target_box(target, scene, volume::Grid::load(fine_desc.file, fine_desc.grid_name));
}

double study_pixel_samples(const StudySpec& spec, int width, int height) {
  // Every candidate each family makes at each factor (the albedo-corrected at every factor: an
  // upper bound where fewer are fitted), counted as run_study counts its renders (study_spp_sum).
  std::vector<std::string> names{"fine", "slab-gamma"};
  for (const std::string& family : candidate_families(spec)) {
    if (family == "fine" || family == "slab-gamma") continue;
    for (const int f : spec.factors) names.push_back(fmt::format("{}-{}x", family, f));
  }
  return static_cast<double>(width) * height * static_cast<double>(study_spp_sum(spec, names));
}

std::size_t candidate_count(const StudySpec& spec, std::size_t albedo_candidates) {
  // The fine grid and the slab; per factor the exponential, shadow-corrected and
  // shadow-directional grids and a local-gamma candidate per memory rule; the albedo-corrected.
  return 2 + (3 + spec.memory_rules.size()) * spec.factors.size() + albedo_candidates;
}

StudyResult run_study(const SceneDesc& scene, const StudySpec& requested, ProgressSink& progress) {
  check_study_spec(requested);
  check_study_scene(scene, requested);
  const Target target = find_target(scene);
  const MediumDesc& fine_desc = scene.media.at(target.medium);
  const volume::Grid fine = volume::Grid::load(fine_desc.file, fine_desc.grid_name);
  if (fine.active_voxel_count() == 0) fail("study: grid '{}' has no active voxels", fine_desc.file);
  StudySpec spec = requested;
  spec.factors = factors_for_grid(requested, fine);
  // The statistics scale: the yarn diameter of the grid's provenance, as `weft validate`.
  const volume::Provenance provenance = volume::read_provenance(fine);
  // No silent voxel-dependent fallback (as validate): a grid without a yarn diameter is refused
  // with what to pass, in the asker's spelling of the study's window.
  const fit::StatisticsScale scale =
      fit::resolve_scale(spec.scale, fine, provenance, progress, spec.front, fit::kStudyWindowOption);
  // The window is used as validate uses it (fit::scale_use: clamped to one voxel .. the active
  // box per axis), and a clamp is said before the renders and kept in the report's notes, as
  // validate and fit warn and record it: a window is never changed in silence.
  const fit::ScaleUse scale_used =
      fit::scale_use(scale, fine, /*local_models=*/true, spec.front, fit::kStudyWindowOption);
  for (const std::string& note : scale_used.notes) say(spec, "warning: " + note);
  const bool root = dist::is_root();
  // A study that fails leaves no half of its grids, fields and scenes behind (they are not
  // resumable: each run writes them afresh).
  FolderRollback outputs(spec.work_dir, root);

  StudyResult result;
  result.notes = scale_used.notes;
  result.sigma = target.sigma_stats;
  result.mode = spec.spp > 0
                    ? fmt::format("fixed {} spp per candidate (equal samples, not equal time)", spec.spp)
                    : fmt::format("time budget of {:.3g} s per candidate (passes of 1 spp until spent)", spec.seconds);

  // The length used (clamped as said above), as validate's `window.length_used`.
  result.scale = (scale_used.length[0] + scale_used.length[1] + scale_used.length[2]) / 3.0;

  // (c) The best model of `weft validate` on the fine grid, chosen against the ground truth
  // (fit::best_by_ground_truth: labelled so in the report, docs/architecture.md).
  fit::ValidationSpec vspec;
  vspec.sigma = target.sigma_stats;
  vspec.scale = scale.length;
  vspec.models = fit::ModelSelection::all().without("least-squares").without("isotropic");
  const fit::Validation validation = fit::validate(fine, vspec, progress);
  std::map<std::string, std::pair<int, double>> votes;  // name → (axes, sum of ratios)
  for (const auto& axis : validation.axes) {
    const fit::ModelRatio best = fit::best_by_ground_truth(axis);
    result.best_by_ground_truth_per_axis.emplace_back(axis.label, best.name);
    votes[best.name].first += 1;
    votes[best.name].second += best.ratio;
  }
  std::pair<int, double> chosen{0, 0.0};
  for (const auto& [name, v] : votes) {
    if (v.first > chosen.first || (v.first == chosen.first && v.second / v.first < chosen.second / chosen.first)) {
      result.best_by_ground_truth = name;
      chosen = v;
    }
  }
  if (result.best_by_ground_truth == "local-gamma") {
    result.best_by_ground_truth_note = "(c) is local-gamma, the same fields as (b) local-gamma-Nx: not rendered twice";
  } else if (result.best_by_ground_truth == "local-exponential") {
    result.best_by_ground_truth_note =
        "(c) is local-exponential, the same grids as (a) exponential-Nx: not rendered twice";
  } else {
    result.best_by_ground_truth_note = fmt::format(
        "(c) is {}, which has no local-field medium in the renderer: not rendered (only local-gamma and "
        "local-exponential do)",
        result.best_by_ground_truth);
  }
  say(spec, fmt::format("best model of validate by the ground truth: {}; {}", result.best_by_ground_truth,
                        result.best_by_ground_truth_note));

  // (d) The slab's law: pooled window statistics of the three axes at scale L (the isotropic
  // gamma law of `weft validate`), over the grid's active box.
  std::vector<fit::ConcentrationStats> per_axis;
  per_axis.reserve(3);
  for (int a = 0; a < 3; ++a)
    per_axis.push_back(fit::window_stats(fine, a, scale.length[static_cast<std::size_t>(a)], progress));
  const fit::ConcentrationStats pooled = fit::pool(per_axis);
  const fit::GammaFit slab = fit::gamma_from_moments(pooled.mean, pooled.variance, target.sigma_stats);
  result.slab_mean_concentration = slab.mean_concentration;
  result.slab_var_concentration = slab.var_concentration;
  result.slab_alpha = slab.alpha;

  // The candidates' scenes (rank 0 writes their grids and fields; every rank reads them after).
  struct Plan {
    StudyCandidate c;
    json scene;
  };
  std::vector<Plan> plans;
  const json& base_medium = target.medium_json;
  {
    Plan p;
    p.c.name = "fine";
    p.c.model = "fine grid";
    p.c.factor = 1;
    p.scene = target.scene;
    plans.push_back(std::move(p));
  }
  for (const int f : spec.factors) {
    const fs::path grid_file = fs::absolute(spec.work_dir / fmt::format("grid_{}x.vdb", f));
    const fs::path fields_file = fs::absolute(spec.work_dir / fmt::format("fields_{}x.vdb", f));
    const fs::path shadow_file = fs::absolute(spec.work_dir / fmt::format("shadow_{}x.vdb", f));
    const fs::path directional_file = fs::absolute(spec.work_dir / fmt::format("shadow_axes_{}x.vdb", f));
    const volume::Grid coarse = volume::downsample(fine, f);
    const volume::ShadowedGrids shadowed_grids = volume::shadowed_downsample(fine, f, target.sigma_stats);
    const volume::Grid& shadowed = shadowed_grids.isotropic;
    if (root) {
      coarse.save(grid_file);
      shadowed.save(shadow_file);
      volume::save_grids({shadowed_grids.per_axis.begin(), shadowed_grids.per_axis.end()}, directional_file);
      const fit::LocalFields fields = fit::local_fields(fine, f, progress);
      fit::save_local_fields(fields, fields_file, fit::FieldChannels::render);  // what the medium reads
    }
    const Box box = union_box(target.box, world_box(coarse));
    Plan e;
    e.c.name = fmt::format("exponential-{}x", f);
    e.c.model = "exponential";
    e.c.factor = f;
    json em = base_medium;
    em["file"] = grid_file.string();
    em.erase("grid");
    e.scene = candidate_scene(target, em, box);
    plans.push_back(std::move(e));
    Plan g;
    g.c.name = fmt::format("local-gamma-{}x", f);
    g.c.model = "local-gamma";
    g.c.factor = f;
    json gm = {{"type", "local-gamma"},
               {"fields", fields_file.string()},
               {"sigma", target.sigma_stats},
               {"albedo", base_medium.at("albedo")},
               {"g", base_medium.at("g")}};
    for (const transmittance::MemoryRule rule : spec.memory_rules) {
      const std::string rule_name(transmittance::memory_rule_name(rule));
      const bool plain = rule == transmittance::kDefaultMemoryRule;  // local-gamma-Nx: the medium's default
      Plan gr = g;
      gr.c.name = plain ? g.c.name : fmt::format("local-gamma-{}-{}x", rule_name, f);
      gr.c.model = plain ? g.c.model : "local-gamma " + rule_name;
      gm["memory"] = rule_name;
      gr.scene = candidate_scene(target, gm, box);
      plans.push_back(std::move(gr));
    }
    // The baselines of docs/render.md §6d: exponential-Nx's medium with another grid or albedo.
    const auto baseline = [&](const std::string& model, const json& medium) {
      Plan b;
      b.c.name = fmt::format("{}-{}x", model, f);
      b.c.model = model;
      b.c.factor = f;
      b.scene = candidate_scene(target, medium, box);  // the same blocks as exponential-Nx
      return b;
    };
    json shadow_medium = em;
    shadow_medium["file"] = shadow_file.string();
    plans.push_back(baseline("shadow-corrected", shadow_medium));
    // The same correction kept per axis, σ(ω) = Σ_a ω_a² σ'_a (docs/render.md §6d): 3 channels.
    json directional_medium = em;
    directional_medium["file"] = directional_file.string();
    // A direction-dependent extinction is sampled by delta tracking only (docs/render.md §5): the
    // scene's tracking is an estimator's choice, unbiased either way, so this candidate uses the
    // default whatever the fine scene asked for.
    directional_medium.erase("tracking");
    directional_medium["axis_grids"] = json::array();
    for (const volume::Grid& g : shadowed_grids.per_axis) directional_medium["axis_grids"].push_back(g.name());
    plans.push_back(baseline("shadow-directional", directional_medium));
    for (const auto& [fa, k] : spec.albedo_factors) {
      if (fa != f) continue;
      json albedo_medium = em;
      const Rgb albedo = corrected_albedo(fine_desc.albedo, k);
      albedo_medium["albedo"] = json::array({albedo[0], albedo[1], albedo[2]});
      // Channels reach 1 one by one below albedo_k_max (by design, albedo_fit.h): said, since the
      // correction then changes the albedo's colour, not only its level.
      if ((fine_desc.albedo * k > 1.0).any())
        say(spec, fmt::format(
                      "albedo-corrected-{}x: k = {:g} clamps the albedo ({:g}, {:g}, {:g}) to ({:g}, {:g}, {:g})", f, k,
                      fine_desc.albedo[0], fine_desc.albedo[1], fine_desc.albedo[2], albedo[0], albedo[1], albedo[2]));
      Plan al = baseline("albedo-corrected", albedo_medium);
      al.c.albedo_factor = k;
      al.c.fitted_to_images = true;
      plans.push_back(std::move(al));
    }
  }
  {
    Plan s;
    s.c.name = "slab-gamma";
    s.c.model = "homogeneous gamma";
    s.c.factor = 0;
    const json law = slab.exponential() ? json{{"name", "exponential"}, {"mu", slab.mean_extinction()}}
                                        : json{{"name", "gamma"},
                                               {"sigma", target.sigma_stats},
                                               {"mean_concentration", slab.mean_concentration},
                                               {"var_concentration", slab.var_concentration}};
    json sm = {{"type", "homogeneous"}, {"law", law}, {"albedo", base_medium.at("albedo")}, {"g", base_medium.at("g")}};
    s.scene = candidate_scene(target, sm, world_box(fine));
    plans.push_back(std::move(s));
  }
  // Every rank waits for rank 0's files (root_decides is a collective).
  (void)dist::root_decides(true);

  const auto parse = [&](const json& j, const std::string& name) {
    // Named with the study's scene, so its errors point at the file the camera came from.
    return parse_scene(j.dump(), fmt::format("{}: study candidate '{}'", scene.source, name), scene.base_dir);
  };
  // Every candidate's scene is read before the first render, so one it cannot take is refused
  // before minutes of renders, not after them.
  for (const Plan& p : plans) (void)parse(p.scene, p.c.name);
  const fs::path files_root = resolved_folder(spec.files_root.empty() ? spec.work_dir : spec.files_root);
  const auto write_scene = [&](const json& j, int spp, std::uint64_t seed, const fs::path& path) {
    if (!root) return;
    json w = j;
    w["integrator"]["spp"] = spp;
    w["integrator"]["seed"] = seed;
    name_files_relative(w, files_root, resolved_folder(path.parent_path()));
    write_text_atomically(path, w.dump(2) + "\n");
  };

  // Every render's pixel samples, known beforehand with a fixed spp: the reference (and its
  // components), the background, images A and B of each candidate and their components.
  const bool components = !spec.components.empty();
  std::uint64_t spp_sum = 0;
  if (spec.spp > 0) {
    std::vector<std::string> names;
    names.reserve(plans.size());
    for (const Plan& p : plans) names.push_back(p.c.name);
    spp_sum = study_spp_sum(spec, names);
  }
  const auto pixels = static_cast<std::uint64_t>(scene.camera.width) * static_cast<std::uint64_t>(scene.camera.height);
  RenderProgress renders(progress, pixels * spp_sum);

  // The reference: the fine grid, many samples, its own seed.
  result.reference_seed = spec.seed + 2 * kSeedStep;
  {
    say(spec, fmt::format("rendering the reference (fine grid) at {} spp", spec.reference_spp));
    RenderOptions ro;
    ro.spp = spec.reference_spp;
    ro.seed = result.reference_seed;
    const RenderResult r = renders.run(pixels * spec.reference_spp, [&](ProgressSink& sink) {
      return render::render(parse(target.scene, "reference"), ro, sink);
    });
    result.reference = r.image;
    result.reference_seconds = r.stats.seconds;
    result.reference_mean = image_mean(r.image);
    result.reference_scene = fs::absolute(spec.work_dir / "reference.json");
    write_scene(target.scene, spec.reference_spp, result.reference_seed, result.reference_scene);
  }
  ComponentRenders reference_components;
  if (components) {
    say(spec, "rendering the reference's components (albedo 0, at most one scattering event)");
    reference_components = renders.run(pixels * spec.reference_spp, [&](ProgressSink& sink) {
      return render_components(target.scene, target.medium, spec.reference_spp, result.reference_seed, scene.base_dir,
                               sink);
    });
  }
  const Image& reference = result.reference;
  {
    // The cloth's pixels: the reference against the same scene without the cloth's box.
    say(spec, "rendering the background (the scene without the cloth)");
    json bare = target.scene;
    bare["shapes"].erase(target.shape);
    RenderOptions ro;
    ro.spp = background_spp(spec);
    ro.seed = result.reference_seed + kSeedStep;
    const Image bg = renders
                         .run(pixels * background_spp(spec),
                              [&](ProgressSink& sink) { return render::render(parse(bare, "background"), ro, sink); })
                         .image;
    const std::size_t pixels = reference.rgb.size() / 3;
    result.cloth_mask.assign(pixels, false);
    double sum = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t c = 0; c < 3; ++c) {
        const std::size_t i = 3 * p + c;
        const double var = (reference.variance.empty() ? 0.0 : reference.variance[i]) + bg.variance[i];
        if (std::abs(reference.rgb[i] - bg.rgb[i]) > 5.0 * std::sqrt(var) + 1e-6) result.cloth_mask[p] = true;
      }
      if (!result.cloth_mask[p]) continue;
      ++result.cloth_pixels;
      for (std::size_t c = 0; c < 3; ++c) sum += reference.rgb[3 * p + c];
    }
    // With no pixel of cloth every cloth statistic is 0, which would read as "unbiased".
    if (result.cloth_pixels == 0)
      fail(
          "study: the cloth covers no pixel of the {}x{} film that the reference tells apart from the scene without "
          "the cloth's box (by 5 standard errors): the camera does not see the cloth, or the reference at {} spp is "
          "too noisy to show it; point the camera at the cloth or raise the reference spp",
          reference.width, reference.height, spec.reference_spp);
    result.cloth_mean = sum / (3.0 * static_cast<double>(result.cloth_pixels));
  }

  for (Plan& p : plans) {
    StudyCandidate& c = p.c;
    const World s = build_world(parse(p.scene, c.name));  // built once, rendered twice
    c.seed_a = spec.seed;
    c.seed_b = spec.seed + kSeedStep;
    RenderOptions oa;
    oa.seed = c.seed_a;
    if (spec.spp > 0) {
      oa.spp = spec.spp;
    } else {
      oa.spp = spec.max_spp;
      oa.time_budget_seconds = spec.seconds;
    }
    oa.on_pass = [&](int done, double seconds, const Image& image) {
      if ((done & (done - 1)) != 0) return;  // powers of two: even spacing on log axes
      c.curve.push_back({done, seconds, rmse_against_noisy_reference(image, reference)});
    };
    say(spec, fmt::format("rendering {} ({})", c.name,
                          spec.spp > 0 ? fmt::format("{} spp", spec.spp) : fmt::format("{:.3g} s", spec.seconds)));
    const std::clock_t cpu0 = std::clock();
    const auto samples = pixels * static_cast<std::uint64_t>(spec.spp);  // per image (fixed spp)
    const RenderResult a = renders.run(samples, [&](ProgressSink& sink) { return render::render(s, oa, sink); });
    c.cpu_seconds = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    c.spp = a.stats.spp;
    c.seconds = a.stats.seconds;
    RenderOptions ob;
    ob.seed = c.seed_b;
    ob.spp = c.spp;
    const RenderResult b = renders.run(samples, [&](ProgressSink& sink) { return render::render(s, ob, sink); });
    // The components of A and B (collective renders, on every rank).
    const bool split = splits_components(spec.components, c.name);
    ComponentRenders ca;
    ComponentRenders cb;
    if (split) {
      say(spec, fmt::format("rendering {}'s components", c.name));
      const auto split_renders = [&](std::uint64_t seed) {
        return renders.run(samples, [&](ProgressSink& sink) {
          return render_components(p.scene, target.medium, c.spp, seed, scene.base_dir, sink);
        });
      };
      ca = split_renders(c.seed_a);
      cb = split_renders(c.seed_b);
    }
    c.scene_file = fs::absolute(spec.work_dir / (c.name + ".json"));
    write_scene(p.scene, c.spp, c.seed_a, c.scene_file);
    if (!root) continue;  // images live on rank 0
    // Its memory from the files its scene names: one count for every candidate, the study's and the matrix's.
    const RepresentationMemory memory = representation_memory(c.scene_file, target.medium);
    c.memory_bytes = memory.values;
    c.memory_tree_bytes = memory.tree;
    c.memory_channels = memory.channels;
    c.image = a.image;
    c.rmse_raw = rmse(a.image, reference);
    c.rmse = rmse_against_noisy_reference(a.image, reference);
    if (c.curve.empty() || c.curve.back().spp != c.spp) c.curve.push_back({c.spp, c.seconds, c.rmse});
    c.noise = std::sqrt(mean_square(a.image, b.image) / 2.0);
    const BiasEstimate be = estimate_bias(a.image, b.image, reference);
    c.bias_sq = be.bias_sq;
    c.bias_sq_stderr = be.stderr_sq;
    c.bias = std::sqrt(std::max(0.0, be.bias_sq));
    const BiasEstimate cloth = estimate_bias(a.image, b.image, reference, &result.cloth_mask);
    c.cloth_bias_sq = cloth.bias_sq;
    c.cloth_bias_sq_stderr = cloth.stderr_sq;
    c.cloth_bias = std::sqrt(std::max(0.0, cloth.bias_sq));
    c.cloth_rmse = std::sqrt(std::max(0.0, cloth.error_sq));
    c.cloth_noise = std::sqrt(std::max(0.0, cloth.noise_sq));
    for (std::size_t i = 0; i < reference.rgb.size(); ++i)
      if (result.cloth_mask[i / 3]) c.cloth_difference += 0.5 * (a.image.rgb[i] + b.image.rgb[i]) - reference.rgb[i];
    if (result.cloth_pixels > 0) c.cloth_difference /= 3.0 * result.cloth_pixels;
    c.cloth_scales = bias_by_scale(a.image, b.image, reference, result.cloth_mask);
    if (c.factor == 1)  // the fine grid's own images, smoothed to each factor's block
      result.resolution_floors =
          resolution_floors(a.image, b.image, reference, result.cloth_mask, scene.camera,
                            0.5 * (target.box.min + target.box.max), fine.voxel_size(), spec.factors);
    c.error_map = abs_difference(a.image, reference);
    if (split)
      c.components = component_biases(a.image, b.image, reference, ca, cb, reference_components, result.cloth_mask);
  }
  for (Plan& p : plans) result.candidates.push_back(std::move(p.c));
  outputs.keep();
  if (!root) return result;

  judge_study(result);
  return result;
}

}  // namespace weft::study
