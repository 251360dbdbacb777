// Render throughput on small versions of the example scenes: samples/s and rays/s (counters),
// the cost of non-exponential vs exponential media, and the surface-only specialisation; and the
// path tracer's kernels alone: a free flight + shadow transmittance per medium kind, and Embree
// ray queries. scripts/bench reads the ratios from these names (keep them stable).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <filesystem>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/render/builtin_scenes.h"
#include "weft/render/geometry.h"
#include "weft/render/medium.h"
#include "weft/render/render.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace {

using namespace weft::render;

void run(benchmark::State& state, SceneDesc scene, IntegratorChoice choice = IntegratorChoice::automatic) {
  scene.camera.width = 64;
  scene.camera.height = 64;
  RenderOptions options;
  options.spp = 4;
  options.integrator = choice;
  std::uint64_t paths = 0;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    const RenderResult r = render(scene, options);
    paths += r.stats.paths;
    rays += r.stats.rays;
    benchmark::DoNotOptimize(r.image.rgb.data());
  }
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(paths), benchmark::Counter::kIsRate);
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
}

SceneDesc builtin(const std::string& name) { return parse_scene(builtin_scene(name), name, "."); }

/// The Cornell box with all three cubes filled with one law (same mean extinction).
SceneDesc cornell_with(const std::string& law_json) {
  SceneDesc s = builtin("cornell_media");
  const SceneDesc one =
      parse_scene(fmt::format(R"({{"media": {{"m": {{"law": {}, "albedo": 0.9}}}}}})", law_json), "bench law", ".");
  for (auto& [name, medium] : s.media) medium = one.media.at("m");
  return s;
}

void BM_CornellExponential(benchmark::State& state) { run(state, cornell_with(R"({"name": "exponential", "mu": 4})")); }
void BM_CornellGammaReciprocal(benchmark::State& state) {
  run(state, cornell_with(R"({"name": "gamma", "mean_extinction": 4, "alpha": 0.5})"));
}
void BM_CornellLinearReciprocal(benchmark::State& state) {
  run(state, cornell_with(R"({"name": "linear", "mean_extinction": 4})"));
}

/// Surface-only scene (media removed).
SceneDesc surfaces_only() {
  SceneDesc s = builtin("cornell_media");
  std::erase_if(s.shapes, [](const ShapeDesc& shape) { return !shape.interior.empty(); });
  s.media.clear();
  return s;
}
/// ... rendered by the `surfaces` specialisation (no medium code compiled in) ...
void BM_CornellSurfacesOnly(benchmark::State& state) { run(state, surfaces_only()); }
/// ... and by the fully general integrator, as a build without specialisation would.
void BM_CornellSurfacesOnlyGeneralIntegrator(benchmark::State& state) {
  run(state, surfaces_only(), IntegratorChoice::general);
}

void BM_ClothPatch(benchmark::State& state) { run(state, builtin("cloth_patch")); }
void BM_Furnace(benchmark::State& state) { run(state, builtin("furnace")); }

/// One medium-vertex step of the integrator's homogeneous branch (integrator.cpp): a free flight
/// from a scatterer (the fast path −log ξ/μ for exponential media, else the pair's sampler and,
/// outside reciprocal mode, its weights) and the transmittance of a shadow segment leaving it.
void free_flight(benchmark::State& state, const MediumDesc& desc) {
  std::shared_ptr<const Medium> built;
  try {
    built = make_medium(desc, "benchmark medium");
  } catch (const weft::Error& e) {
    state.SkipWithError(e.what());
    return;
  }
  const Medium& m = *built;
  const std::unique_ptr<MediumScratch> scratch = m.make_scratch();
  weft::Pcg32 rng = weft::stream_for(11, 0);
  constexpr auto origin = weft::transmittance::Origin::scatterer;
  const Vec3 o(0, 0, 0);
  const Vec3 d(0, 0, 1);
  for (auto _ : state) {
    const double t_hit = 2.0 * rng.uniform();  // distance to the next surface, in mean free paths / 2
    const Flight f = m.sample_flight(o, d, t_hit, origin, rng, scratch.get());
    double beta = f.weight;
    const double segment = 2.0 * rng.uniform();
    beta *= m.transmittance(o, d, segment, origin, rng, scratch.get());
    benchmark::DoNotOptimize(f.t);
    benchmark::DoNotOptimize(beta);
  }
  state.SetItemsProcessed(state.iterations());
}

MediumDesc medium_with(weft::transmittance::LawSpec law, weft::transmittance::Origin given) {
  MediumDesc desc;
  desc.law = std::move(law);
  desc.given = given;
  return desc;
}

// Mean free path 1 for every kind; gamma α = 0.5 is strongly positively correlated. The
// gamma-path law (k = 2) is given as the scatterer law T_S: as a source law its p_Q(0) = 0 and
// no reciprocal T_S exists.
const bool kFreeFlightRegistered = [] {
  using weft::transmittance::Origin;
  struct Kind {
    std::string name;
    weft::transmittance::LawSpec law;
    Origin given;
  };
  const std::vector<Kind> kinds{
      {"exponential", {"exponential", {{"mu", 1.0}}, "", ""}, Origin::source},
      {"gamma", {"gamma", {{"mean_extinction", 1.0}, {"alpha", 0.5}}, "", ""}, Origin::source},
      {"linear", {"linear", {{"mean_extinction", 1.0}}, "", ""}, Origin::source},
      {"gamma-path", {"gamma-path", {{"k", 2.0}, {"theta", 0.5}}, "", ""}, Origin::scatterer},
  };
  for (const auto& k : kinds) {
    benchmark::RegisterBenchmark(("BM_FreeFlight/" + k.name).c_str(),
                                 [desc = medium_with(k.law, k.given)](benchmark::State& s) { free_flight(s, desc); });
  }
  return true;
}();

/// A local-gamma medium's flight + shadow transmittance (LocalGammaField's DDA walk over the
/// coarse fields) on rays in random directions from random points of a 32³ field of varying
/// C̄ and V (a fixed hash pattern; mean free path ≈ 0.2 of the box side), so each flight
/// crosses a few to a few dozen coarse voxels. items/s = flights (each with its shadow segment).
void BM_LocalGammaFlight(benchmark::State& state) {
  constexpr int n = 32;
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "weft_bench_local_fields.vdb";
  std::vector<weft::volume::Grid> grids;
  for (const std::string name :
       {"mean_concentration", "var_concentration_x", "var_concentration_y", "var_concentration_z"}) {
    weft::volume::Grid g(1.0 / n, name);
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const unsigned hsh = (static_cast<unsigned>(i) * 73856093U) ^ (static_cast<unsigned>(j) * 19349663U) ^
                               (static_cast<unsigned>(k) * 83492791U);
          const float c = 0.05F + 0.4F * static_cast<float>(hsh % 1000U) / 1000.0F;
          g.set_value(i, j, k, name == "mean_concentration" ? c : 0.3F * c * c);
        }
    grids.push_back(g);
  }
  weft::volume::save_grids(grids, file);
  MediumDesc desc;
  desc.kind = MediumKind::local_gamma;
  desc.file = file.string();
  desc.sigma = 20.0;
  const std::shared_ptr<const Medium> m = make_medium(desc, "benchmark medium");
  const std::unique_ptr<MediumScratch> scratch = m->make_scratch();
  weft::Pcg32 rng = weft::stream_for(13, 0);
  std::vector<Vec3> o;
  std::vector<Vec3> d;
  for (int i = 0; i < 4096; ++i) {
    o.emplace_back(0.1 + 0.8 * rng.uniform(), 0.1 + 0.8 * rng.uniform(), 0.1 + 0.8 * rng.uniform());
    const double z = 1.0 - 2.0 * rng.uniform();
    const double phi = 2.0 * std::numbers::pi * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    d.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & 4095U;
    const Flight f = m->sample_flight(o[k], d[k], 1.0, weft::transmittance::Origin::source, rng, scratch.get());
    const double tr = m->transmittance(o[k], d[k], 0.5, weft::transmittance::Origin::scatterer, rng, scratch.get());
    benchmark::DoNotOptimize(f.t);
    benchmark::DoNotOptimize(tr);
  }
  state.SetItemsProcessed(state.iterations());
  std::filesystem::remove(file);
}
BENCHMARK(BM_LocalGammaFlight);

/// Embree ray queries in the Cornell box with its media cubes: rays from random points inside
/// the box in uniform random directions (closest hit, and any hit over half the box size).
struct CornellGeometry {
  CornellGeometry() : scene(builtin("cornell_media")) {
    std::map<std::string, int> materials;
    std::map<std::string, int> media;
    for (const auto& [name, m] : scene.materials) materials.emplace(name, static_cast<int>(materials.size()));
    for (const auto& [name, m] : scene.media) media.emplace(name, static_cast<int>(media.size()));
    geometry = std::make_unique<Geometry>(scene, materials, media);
  }
  SceneDesc scene;
  std::unique_ptr<Geometry> geometry;
};

const Geometry& cornell_geometry() {
  static const CornellGeometry g;
  return *g.geometry;
}

/// Random rays, precomputed so the loop times the query alone.
struct RayBatch {
  std::vector<Vec3> o;
  std::vector<Vec3> d;
};
RayBatch random_rays(double extent) {
  RayBatch b;
  weft::Pcg32 rng = weft::stream_for(12, 0);
  for (int i = 0; i < 4096; ++i) {
    b.o.emplace_back((rng.uniform() - 0.5) * 0.5 * extent, (rng.uniform() - 0.5) * 0.5 * extent,
                     (rng.uniform() - 0.5) * 0.5 * extent);
    const double z = 1.0 - 2.0 * rng.uniform();
    const double phi = 2.0 * std::numbers::pi * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    b.d.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
  }
  return b;
}

void BM_EmbreeIntersect(benchmark::State& state) {
  const Geometry& g = cornell_geometry();
  const RayBatch rays = random_rays(g.extent());
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & 4095U;
    benchmark::DoNotOptimize(g.intersect(rays.o[k], rays.d[k], 1e-6, std::numeric_limits<double>::infinity()));
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_EmbreeOccluded(benchmark::State& state) {
  const Geometry& g = cornell_geometry();
  const RayBatch rays = random_rays(g.extent());
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & 4095U;
    benchmark::DoNotOptimize(g.occluded(rays.o[k], rays.d[k], 1e-6, 0.5 * g.extent()));
  }
  state.SetItemsProcessed(state.iterations());
}

// Whole renders take ~10–60 ms per iteration: scripts/bench sets --benchmark_min_time for them.
BENCHMARK(BM_CornellSurfacesOnly)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CornellSurfacesOnlyGeneralIntegrator)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CornellExponential)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CornellGammaReciprocal)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CornellLinearReciprocal)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ClothPatch)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Furnace)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EmbreeIntersect);
BENCHMARK(BM_EmbreeOccluded);

}  // namespace
