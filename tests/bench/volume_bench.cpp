// Axis beams through the default cloth: one streaming pass over the active voxels vs per-ray
// traversal (weft's hierarchical DDA, and openvdb::math::DDA<Ray, 0> with a value accessor).
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

void axis_beam(benchmark::State& state, weft::volume::BeamMethod method) {
  const auto& grid = cloth_grid();
  weft::volume::BeamSpec spec;
  spec.direction = {0.0, 0.0, 0.0};
  spec.direction[static_cast<std::size_t>(state.range(0))] = 1.0;
  spec.scale = 100.0;
  spec.method = method;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    const auto curve = weft::volume::measure_beam(grid, spec);
    benchmark::DoNotOptimize(curve.log_t.back());
    rays = curve.rays;
  }
  const auto box = grid.active_bbox().extent();
  const double voxels = static_cast<double>(box[0] * box[1] * box[2]);
  state.counters["rays"] = static_cast<double>(rays);
  state.counters["box_voxels_per_s"] =
      benchmark::Counter(voxels * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_AxisBeamStreaming(benchmark::State& s) { axis_beam(s, weft::volume::BeamMethod::streaming); }
void BM_AxisBeamWeftDda(benchmark::State& s) { axis_beam(s, weft::volume::BeamMethod::per_ray); }
void BM_AxisBeamOpenVdbDda(benchmark::State& s) { axis_beam(s, weft::volume::BeamMethod::openvdb_dda); }

}  // namespace

// Argument: axis (0 = x, 2 = z).
BENCHMARK(BM_AxisBeamStreaming)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AxisBeamWeftDda)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AxisBeamOpenVdbDda)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
