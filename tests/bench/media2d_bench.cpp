// Throughput of the 2D media pieces: generation, grid build, and ray tracing (free paths from
// sources). Media of the --quick size (r = 1e-4, λ = 0.025: about 2·10⁵ disks).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "data_gen/media2d/disk_grid.h"
#include "data_gen/media2d/medium.h"

namespace {

using namespace weft::media2d;

MediumSpec spec_for(double eta) { return MediumSpec{eta, 1e-4, 0.025, 1000, 0.0}; }

void BM_Generate(benchmark::State& state) {
  const double eta = static_cast<double>(state.range(0)) / 10.0;
  for (auto _ : state) {
    weft::Pcg32 rng(1);
    const Medium m = generate(spec_for(eta), rng);
    benchmark::DoNotOptimize(m.centers.data());
    state.SetItemsProcessed(state.items_processed() + static_cast<std::int64_t>(m.centers.size()));
  }
}
BENCHMARK(BM_Generate)->Arg(-5)->Arg(0)->Arg(5)->Unit(benchmark::kMillisecond);

void BM_GridBuild(benchmark::State& state) {
  weft::Pcg32 rng(2);
  const Medium m = generate(spec_for(0.0), rng);
  for (auto _ : state) {
    const DiskGrid grid(m);
    benchmark::DoNotOptimize(&grid);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(m.centers.size()));
}
BENCHMARK(BM_GridBuild)->Unit(benchmark::kMillisecond);

void BM_TraceFreePath(benchmark::State& state) {
  weft::Pcg32 rng(3);
  const Medium m = generate(spec_for(static_cast<double>(state.range(0)) / 10.0), rng);
  const DiskGrid grid(m);
  weft::Pcg32 rays(4);
  for (auto _ : state) {
    const Point2 o{rays.uniform(), rays.uniform()};
    const double phi = 2.0 * std::numbers::pi * rays.uniform();
    benchmark::DoNotOptimize(grid.first_hit(o, {std::cos(phi), std::sin(phi)}, 1.0));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TraceFreePath)->Arg(-5)->Arg(0)->Arg(5);

}  // namespace
