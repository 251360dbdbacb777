#include "weft/study/corpus.h"

#include <algorithm>
#include <chrono>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/grid_fibres.h"
#include "weft/core/error.h"
#include "weft/dist/distributed.h"
#include "weft/fibres/fibre_beam.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/volume/provenance.h"

namespace weft::study {
using namespace weft::cloth;  // NOLINT(google-build-using-namespace)
namespace {

using nlohmann::json;

// A case's result crosses ranks (and the --resume store) as MessagePack: doubles round-trip
// exactly (nlohmann writes float32 only when that is exact, float64 otherwise, NaN included), so
// rank 0 writes the same digits as a one-process run.
json ratio_json(const fit::ModelRatio& m) {
  return {{"name", m.name}, {"rms", m.rms_abs_t}, {"ratio", m.ratio}, {"gt", m.uses_ground_truth}};
}

fit::ModelRatio ratio_from(const json& j) {
  fit::ModelRatio m;
  m.name = j.at("name").get<std::string>();
  m.rms_abs_t = j.at("rms").get<double>();
  m.ratio = j.at("ratio").get<double>();
  m.uses_ground_truth = j.at("gt").get<bool>();
  return m;
}

dist::Bytes encode(const CorpusResult& r) {
  json axes = json::array();
  for (const auto& a : r.axes) {
    json models = json::array();
    for (const auto& m : a.models) models.push_back(ratio_json(m));
    axes.push_back({{"axis", a.axis},
                    {"scale", a.scale},
                    {"models", models},
                    {"predicted", ratio_json(a.predicted)},
                    {"best", ratio_json(a.best)},
                    {"fibre", {a.voxel_minus_fibre_rms, a.voxel_minus_fibre_max, a.fibre_stderr_rms}}});
  }
  const json j = {{"sigma", r.sigma}, {"active_voxels", r.active_voxels}, {"seconds", r.seconds}, {"axes", axes}};
  return json::to_msgpack(j);
}

CorpusResult decode(const CorpusCase& c, const dist::Bytes& b) {
  const json j = json::from_msgpack(b);
  CorpusResult r;
  r.c = c;
  r.sigma = j.at("sigma").get<double>();
  r.active_voxels = j.at("active_voxels").get<std::uint64_t>();
  r.seconds = j.at("seconds").get<double>();
  for (const auto& ja : j.at("axes")) {
    CorpusAxis a;
    a.axis = ja.at("axis").get<std::string>();
    a.scale = ja.at("scale").get<double>();
    for (const auto& m : ja.at("models")) a.models.push_back(ratio_from(m));
    a.predicted = ratio_from(ja.at("predicted"));
    a.best = ratio_from(ja.at("best"));
    const auto& f = ja.at("fibre");
    a.voxel_minus_fibre_rms = f.at(0).get<double>();
    a.voxel_minus_fibre_max = f.at(1).get<double>();
    a.fibre_stderr_rms = f.at(2).get<double>();
    r.axes.push_back(std::move(a));
  }
  return r;
}

}  // namespace

std::string CorpusCase::name() const { return fmt::format("{}-{}-{:g}um", pattern, preset, voxel_size * 1000.0); }

std::vector<CorpusCase> corpus_cases(bool quick) {
  std::vector<CorpusCase> out;
  if (quick) {
    for (const char* p : {"plain", "stockinette"}) out.push_back({p, "cotton", 0.02});
    return out;
  }
  for (const char* p : {"plain", "twill21", "twill22", "twill31", "satin5", "basket", "stockinette"}) {
    for (const char* y : {"cotton", "polyester", "wool"}) {
      for (double h : {0.01, 0.02}) out.push_back({p, y, h});
    }
  }
  return out;
}

std::vector<CorpusCase> select_corpus_cases(const std::vector<CorpusCase>& cases,
                                            const std::vector<std::string>& parts) {
  if (parts.empty()) return cases;
  for (const auto& p : parts) {
    if (p.empty()) fail("corpus: an empty case name part");
    const bool any = std::any_of(cases.begin(), cases.end(),
                                 [&](const CorpusCase& c) { return c.name().find(p) != std::string::npos; });
    if (!any) fail("corpus: no case name contains '{}' (names look like {})", p, cases.front().name());
  }
  std::vector<CorpusCase> out;
  for (const auto& c : cases) {
    const std::string n = c.name();
    if (std::any_of(parts.begin(), parts.end(), [&](const std::string& p) { return n.find(p) != std::string::npos; }))
      out.push_back(c);
  }
  return out;
}

CorpusResult run_corpus_case(const CorpusCase& c, std::uint64_t seed, const std::string& window,
                             ProgressSink& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  ClothSpec spec = default_cloth_spec();
  spec.pattern = c.pattern;
  spec.warp_yarn = yarn_preset(c.preset);
  spec.weft_yarn = yarn_preset(c.preset);
  spec.warp_spacing = 0.0;
  spec.weft_spacing = 0.0;
  spec.crimp = 0.0;
  spec.voxel_size = c.voxel_size;
  spec.seed = seed;
  const ClothBuild build = build_cloth(spec, progress);
  if (build.grid.active_voxel_count() == 0) fail("corpus case {}: the voxelized cloth is empty", c.name());
  const auto provenance = volume::read_provenance(build.grid);
  if (!provenance.sigma) fail("corpus case {}: the generated grid has no sigma", c.name());
  fit::ValidationSpec vs;
  vs.sigma = *provenance.sigma;
  vs.seed = seed;
  vs.scale = fit::resolve_scale(window, build.grid, provenance, progress).length;
  const fit::Validation v = fit::validate(build.grid, vs, progress);
  // The fibres the grid was voxelized from, on the voxel beams' own rays (opaque fibres).
  const fibres::CapsuleIndex index(fibre_geometry(build.fibers));
  CorpusResult r;
  r.c = c;
  r.sigma = vs.sigma;
  r.active_voxels = build.grid.active_voxel_count();
  for (const auto& a : v.axes) {
    CorpusAxis ca;
    ca.axis = a.label;
    ca.scale = a.scale;
    ca.models = fit::model_ratios(a);
    ca.predicted = fit::predicted(a);
    ca.best = fit::best_by_ground_truth(a);
    volume::BeamSpec beam;
    beam.direction = a.direction;
    beam.seed = seed;
    const auto d = fibres::curve_difference(
        a.ground_truth, fibres::measure_fibre_beam(index, build.grid, beam, fibres::kOpaque, progress));
    ca.voxel_minus_fibre_rms = d.rms;
    ca.voxel_minus_fibre_max = d.max_abs;
    ca.fibre_stderr_rms = d.rms_stderr_b;
    r.axes.push_back(std::move(ca));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::vector<CorpusResult> run_corpus(const std::vector<CorpusCase>& cases, std::uint64_t seed,
                                     const std::string& window, ProgressSink& progress, dist::UnitStore* store) {
  if (cases.empty()) fail("corpus: no cases");
  ProgressTask task(progress, "corpus cases", cases.size());
  dist::UnitsOptions how;
  how.progress = &task;
  how.store = store;
  how.name = [&](std::size_t u) { return fmt::format("corpus case {} ({})", u, cases[u].name()); };
  // A case runs its stages on the rank's threads too (nested in TBB), so a rank with few cases
  // still uses every thread; its own progress stays silent (cases run side by side).
  const std::vector<dist::Bytes> units = dist::run_units(
      cases.size(), [&](std::size_t u) { return encode(run_corpus_case(cases[u], seed, window)); }, how);
  std::vector<CorpusResult> out;
  if (!dist::is_root()) return out;  // rank 0 gathered every case
  out.reserve(units.size());
  for (std::size_t u = 0; u < units.size(); ++u) out.push_back(decode(cases[u], units[u]));
  return out;
}

}  // namespace weft::study
