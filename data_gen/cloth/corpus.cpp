#include "data_gen/cloth/corpus.h"

#include <chrono>

#include <fmt/core.h>

#include "data_gen/cloth/cloth.h"
#include "weft/core/error.h"
#include "weft/fit/scale.h"
#include "weft/fit/validation.h"
#include "weft/volume/provenance.h"

namespace weft::cloth {

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
  CorpusResult r;
  r.c = c;
  r.sigma = vs.sigma;
  r.active_voxels = build.grid.active_voxel_count();
  for (const auto& a : v.axes) {
    CorpusAxis ca;
    ca.axis = a.label;
    ca.scale = a.scale;
    ca.models = fit::model_ratios(a);
    ca.best = fit::best_predictive(a);
    r.axes.push_back(std::move(ca));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace weft::cloth
