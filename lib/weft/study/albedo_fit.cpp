// Albedo-corrected downsampling: k_N fitted on one scene (albedo_fit.h; docs/render.md §6d).
#include "weft/study/albedo_fit.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <fmt/format.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/dist/distributed.h"
#include "weft/render/render.h"
#include "weft/study/study_target.h"
#include "weft/volume/downsample.h"
#include "weft/volume/grid.h"
#include "weft/volume/lattice.h"

namespace weft::study {
namespace {

namespace fs = std::filesystem;
using render::Image;
using render::RenderOptions;
using render::SceneDesc;

constexpr int kFitSpp = 16;      ///< coarse renders when the study has no fixed spp
constexpr int kMaxRenders = 10;  ///< per factor
/// The reference's seed: any seed other than the coarse renders' gives independent noise
/// (stream_for hashes (seed, index)).
constexpr std::uint64_t kReferenceSeedOffset = 0xA1BED0F17ULL;

/// The mean over all pixels and channels and its standard error. The channels of a pixel share
/// their paths, so their errors are taken as fully correlated (an upper bound).
struct MeanEstimate {
  double mean = 0.0;
  double stderr_ = 0.0;
};

MeanEstimate mean_estimate(const Image& im) {
  MeanEstimate e;
  const std::size_t pixels = im.rgb.size() / 3;
  if (pixels == 0) return e;
  double var = 0.0;
  for (std::size_t p = 0; p < pixels; ++p) {
    double sd = 0.0;
    for (std::size_t c = 0; c < 3; ++c) {
      e.mean += im.rgb[3 * p + c];
      if (!im.variance.empty()) sd += std::sqrt(std::max(0.0F, im.variance[3 * p + c]));
    }
    var += (sd / 3.0) * (sd / 3.0);
  }
  e.mean /= 3.0 * static_cast<double>(pixels);
  e.stderr_ = std::sqrt(var) / static_cast<double>(pixels);
  return e;
}

}  // namespace

double albedo_k_max(const render::Rgb& albedo) {
  double min_albedo = 1.0;
  for (int c = 0; c < 3; ++c)
    if (albedo[c] > 0.0) min_albedo = std::min(min_albedo, albedo[c]);
  return 1.0 / min_albedo;
}

render::Rgb corrected_albedo(const render::Rgb& albedo, double k) { return (albedo * k).cwiseMax(0.0).cwiseMin(1.0); }

std::vector<AlbedoFit> fit_albedo(const SceneDesc& scene, const StudySpec& requested, ProgressSink& progress) {
  check_study_spec(requested);
  check_study_scene(scene);
  // Named copies, not a structured binding: lambdas below capture them (clang < 16 refuses
  // to capture bindings).
  const Target study_target = find_target(scene);
  const std::string medium = study_target.medium;
  const std::size_t shape = study_target.shape;
  const render::MediumDesc& fine_desc = scene.media.at(medium);
  const volume::Grid fine = volume::Grid::load(fine_desc.file, fine_desc.grid_name);
  StudySpec spec = requested;
  spec.factors = factors_for_grid(requested, fine);
  const bool root = dist::is_root();
  FolderRollback outputs(spec.work_dir, root);  // a failed fit leaves no coarse grid behind

  const auto say = [&](const std::string& line) {
    if (spec.log) spec.log(line);
  };
  say(fmt::format("albedo fit: rendering the fine grid at {} spp", spec.reference_spp));
  RenderOptions ro;
  ro.spp = spec.reference_spp;
  ro.seed = spec.seed + kReferenceSeedOffset;
  const MeanEstimate target = mean_estimate(render::render(scene, ro, progress).image);
  const double target_mean = dist::root_value(target.mean);

  const Eigen::Array3d& albedo = fine_desc.albedo;
  const double k_max = albedo_k_max(albedo);

  std::vector<AlbedoFit> fits;
  for (const int f : spec.factors) {
    const volume::Grid coarse = volume::downsample(fine, f);
    const fs::path file = fs::absolute(spec.work_dir / fmt::format("albedo_fit_{}x.vdb", f));
    if (root) coarse.save(file);
    (void)dist::root_decides(true);  // every rank waits for rank 0's file
    SceneDesc s = scene;
    s.media.at(medium).file = file.string();
    s.media.at(medium).grid_name.clear();
    // The coarse grid's blocks may straddle the fine box: grow the box to hold them.
    const volume::WorldBox wb = volume::active_world_box(coarse);
    for (int a = 0; a < 3; ++a) {
      s.shapes[shape].min[a] = std::min(s.shapes[shape].min[a], wb.lo[static_cast<std::size_t>(a)]);
      s.shapes[shape].max[a] = std::max(s.shapes[shape].max[a], wb.hi[static_cast<std::size_t>(a)]);
    }

    AlbedoFit fit;
    fit.factor = f;
    fit.target = target_mean;
    // Each render returns (mean − target) on every rank and records the closest k so far.
    double best_gap = std::numeric_limits<double>::infinity();
    const auto evaluate = [&](double k) {
      s.media.at(medium).albedo = corrected_albedo(albedo, k);
      RenderOptions o;
      o.spp = spec.spp > 0 ? spec.spp : kFitSpp;
      o.seed = spec.seed;
      say(fmt::format("albedo fit {}x: k = {:.6g}", f, k));
      const MeanEstimate m = mean_estimate(render::render(s, o, progress).image);
      ++fit.renders;
      const double mean = dist::root_value(m.mean);
      const double tol = dist::root_value(
          std::max(2.0 * std::sqrt(target.stderr_ * target.stderr_ + m.stderr_ * m.stderr_), 1e-3 * target_mean));
      if (std::abs(mean - target_mean) < best_gap) {
        best_gap = std::abs(mean - target_mean);
        fit.k = k;
        fit.fitted = mean;
        fit.tolerance = tol;
        fit.converged = best_gap <= tol;
      }
      return mean - target_mean;
    };
    // Secant steps inside the bracket [lo, hi] known to hold the root (gap(lo) < 0 < gap(hi),
    // the domain's ends until a render lands on each side). The mean grows with k (more light
    // scattered on), so the sign of a gap says on which side of the root its k lies. Every value
    // below comes from root_value, so every rank takes the same steps.
    double lo = 0.0;
    double hi = k_max;
    double k_prev = 0.0;
    double gap_prev = 0.0;
    bool have_prev = false;
    double k = std::min(1.0, k_max);
    while (fit.renders < kMaxRenders && hi - lo > 1e-6 * k_max) {
      const double gap = evaluate(k);
      if (fit.converged) break;
      (gap < 0.0 ? lo : hi) = k;
      double next = 0.5 * (lo + hi);
      if (have_prev && gap != gap_prev) {
        next = k - gap * (k - k_prev) / (gap - gap_prev);
      } else if (!have_prev && gap + target_mean > 0.0) {
        next = k * target_mean / (gap + target_mean);  // first step: the mean taken ∝ k
      }
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      k_prev = k;
      gap_prev = gap;
      have_prev = true;
      k = next;
    }
    fits.push_back(fit);
  }
  outputs.keep();
  return fits;
}

std::vector<std::pair<int, double>> fit_albedo_factors(const SceneDesc& scene, const StudySpec& spec,
                                                       ProgressSink& progress) {
  std::vector<std::pair<int, double>> out;
  for (const AlbedoFit& f : fit_albedo(scene, spec, progress)) out.emplace_back(f.factor, f.k);
  return out;
}

}  // namespace weft::study
