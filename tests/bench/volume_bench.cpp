// Axis beams through the default cloth: one streaming pass over the active voxels vs per-ray
// traversal (weft's hierarchical DDA, and openvdb::math::DDA<Ray, 0> with a value accessor),
// and the floor of any axis beam: touching every active voxel's value once.
#include <benchmark/benchmark.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <vector>

#include "data_gen/cloth/cloth.h"
#include "weft/core/parallel.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid_openvdb.h"

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

/// One pass over the active voxels: every leaf's active values summed, leaves split into the
/// same 64 fixed shards over the same thread pool as the streaming beam. An axis beam has to
/// read every active voxel at least once, so this is its floor.
void BM_TouchActiveVoxels(benchmark::State& state) {
  const auto& grid = cloth_grid();
  const auto& tree = grid.impl().grid->tree();
  std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
  for (auto it = tree.cbeginLeaf(); it; ++it) leaves.push_back(&*it);
  constexpr std::size_t kShards = 64;
  std::vector<double> partial(kShards);
  for (auto _ : state) {
    weft::parallel_units(kShards, [&](std::size_t shard) {
      double acc = 0.0;
      const std::size_t begin = shard * leaves.size() / kShards;
      const std::size_t end = (shard + 1) * leaves.size() / kShards;
      for (std::size_t l = begin; l < end; ++l) {
        const float* data = leaves[l]->buffer().data();
        for (auto on = leaves[l]->getValueMask().beginOn(); on; ++on) acc += static_cast<double>(data[on.pos()]);
      }
      partial[shard] = acc;
    });
    double total = 0.0;
    for (double p : partial) total += p;
    benchmark::DoNotOptimize(total);
  }
  state.counters["active_voxels"] = static_cast<double>(grid.active_voxel_count());
  state.counters["active_voxels_per_s"] =
      benchmark::Counter(static_cast<double>(grid.active_voxel_count()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}

void BM_AxisBeamStreaming(benchmark::State& s) { axis_beam(s, weft::volume::BeamMethod::streaming); }
void BM_AxisBeamWeftDda(benchmark::State& s) { axis_beam(s, weft::volume::BeamMethod::per_ray); }
void BM_AxisBeamOpenVdbDda(benchmark::State& s) { axis_beam(s, weft::volume::BeamMethod::openvdb_dda); }

}  // namespace

BENCHMARK(BM_TouchActiveVoxels)->Unit(benchmark::kMillisecond)->UseRealTime();
// Argument: axis (0 = x, 2 = z).
BENCHMARK(BM_AxisBeamStreaming)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AxisBeamWeftDda)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AxisBeamOpenVdbDda)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
