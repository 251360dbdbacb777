// Oblique beams through the default cloth: weft's hierarchical Amanatides–Woo DDA per ray vs
// openvdb::math::DDA<Ray, 0> with a value accessor. An oblique beam has no streaming fast path
// (columns do not line up with voxels), so per-ray traversal is the whole cost; this is the
// figure for any direction other than the three axes. Rays: one column in 4×4 (column_stride 4)
// keeps an iteration short; `rays_per_s` is the traversal rate.
#include <array>
#include <cstdint>

#include <benchmark/benchmark.h>

#include "data_gen/cloth/cloth.h"
#include "weft/volume/beam.h"

namespace {

const weft::volume::Grid& cloth_grid() {
  static const weft::volume::Grid grid = [] {
    return weft::cloth::build_cloth(weft::cloth::default_cloth_spec(), weft::null_progress()).grid;
  }();
  return grid;
}

/// Argument 0: (1, 0, 1)/√2, in the plane of the warp and the thickness; 1: (1, 1, 1)/√3.
std::array<double, 3> direction(std::int64_t which) {
  return which == 0 ? std::array<double, 3>{1.0, 0.0, 1.0} : std::array<double, 3>{1.0, 1.0, 1.0};
}

void oblique_beam(benchmark::State& state, weft::volume::BeamMethod method) {
  const auto& grid = cloth_grid();
  weft::volume::BeamSpec spec;
  spec.direction = direction(state.range(0));
  spec.scale = 100.0;
  spec.method = method;
  spec.column_stride = 4;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    const auto curve = weft::volume::measure_beam(grid, spec);
    benchmark::DoNotOptimize(curve.log_t.back());
    rays = curve.rays;
  }
  state.counters["rays"] = static_cast<double>(rays);
  state.counters["rays_per_s"] =
      benchmark::Counter(static_cast<double>(rays * state.iterations()), benchmark::Counter::kIsRate);
}

void BM_ObliqueBeamWeftDda(benchmark::State& s) { oblique_beam(s, weft::volume::BeamMethod::per_ray); }
void BM_ObliqueBeamOpenVdbDda(benchmark::State& s) { oblique_beam(s, weft::volume::BeamMethod::openvdb_dda); }

}  // namespace

BENCHMARK(BM_ObliqueBeamWeftDda)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ObliqueBeamOpenVdbDda)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
