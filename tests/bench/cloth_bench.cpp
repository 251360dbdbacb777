// Voxelizer throughput: fibres/s and voxels/s on real yarns (Google Benchmark).
//   bench_cloth --benchmark_filter=Voxelize
#include <benchmark/benchmark.h>

#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/voxelize.h"
#include "data_gen/cloth/yarn.h"

namespace {
using namespace weft::cloth;

// `yarns` straight cotton yarns 2 mm long, side by side: total fibre length grows linearly
// with the argument, so time per fibre shows whether the voxelizer scales linearly.
FiberSet yarns(int count) {
  FiberSet all;
  for (int i = 0; i < count; ++i) {
    Curve c;
    c.points = {{0.0, 0.4 * i, 0.0}, {2.0, 0.4 * i, 0.05}};
    all.append(yarn_fibers(c, yarn_preset("cotton"), 1, i));
  }
  return all;
}

void BM_VoxelizeCottonYarns(benchmark::State& state) {
  const FiberSet fibers = yarns(static_cast<int>(state.range(0)));
  VoxelizeOptions options;
  options.voxel_size = static_cast<double>(state.range(1)) * 1e-3;
  std::uint64_t voxels = 0;
  for (auto _ : state) {
    VoxelizeReport report;
    const auto grid = voxelize(fibers, options, report);
    voxels = report.active_voxels;
    benchmark::DoNotOptimize(report.grid_volume);
  }
  state.counters["fibres/s"] =
      benchmark::Counter(static_cast<double>(fibers.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["voxels/s"] =
      benchmark::Counter(static_cast<double>(voxels), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["fibre_mm/s"] = benchmark::Counter(fibers.length(), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["active_voxels"] = static_cast<double>(voxels);
}
// (yarns, voxel size in µm)
BENCHMARK(BM_VoxelizeCottonYarns)
    ->Args({1, 10})
    ->Args({2, 10})
    ->Args({4, 10})
    ->Args({2, 5})
    ->Args({2, 20})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_DefaultCloth(benchmark::State& state) {
  const ClothSpec spec = default_cloth_spec();
  for (auto _ : state) {
    const ClothBuild build = build_cloth(spec, weft::null_progress());
    benchmark::DoNotOptimize(build.report.grid_volume);
  }
}
BENCHMARK(BM_DefaultCloth)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

}  // namespace
