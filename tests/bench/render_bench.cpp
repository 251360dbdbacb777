// Render throughput on small versions of the example scenes: samples/s and rays/s (counters),
// the cost of non-exponential vs exponential media, and the surface-only specialisation.
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "weft/render/builtin_scenes.h"
#include "weft/render/render.h"

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

BENCHMARK(BM_CornellSurfacesOnly)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_CornellSurfacesOnlyGeneralIntegrator)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_CornellExponential)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_CornellGammaReciprocal)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_CornellLinearReciprocal)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_ClothPatch)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_Furnace)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

}  // namespace
