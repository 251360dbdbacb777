// Wall time to render pictures to PNG: a transmittance chart and volume views of a woven slab.
// Each iteration renders from scratch (new window, new context), as the app does once per run.

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "weft/core/error.h"
#include "weft/viz/chart.h"
#include "weft/viz/display.h"
#include "weft/viz/volume_view.h"
#include "weft/volume/grid_openvdb.h"

namespace {

namespace fs = std::filesystem;
using namespace weft;

fs::path out_dir() {
  const fs::path dir = fs::temp_directory_path() / "weft_bench_viz";
  fs::create_directories(dir);
  return dir;
}

void require_display(benchmark::State& state) {
  std::string why;
  if (!viz::ensure_display(&why)) state.SkipWithError(why.c_str());
}

viz::Chart transmittance_chart() {
  viz::Chart chart;
  chart.title = "Transmittance";
  chart.x_label = "depth t [mm]";
  chart.y_label = "T(t)";
  chart.log_y = true;
  for (int d = 0; d < 3; ++d) {
    const double alpha = 0.5 + 1.5 * d;
    for (int model = 0; model < 2; ++model) {
      viz::Series s;
      s.label = std::string(model ? "gamma " : "measured ") + "xyz"[d];
      s.style = model ? viz::LineStyle::dotted : viz::LineStyle::solid;
      s.color = {static_cast<unsigned char>(80 * d), 60, static_cast<unsigned char>(200 - 80 * d)};
      for (int i = 0; i <= 200; ++i) {
        const double t = 0.025 * i;
        s.x.push_back(t);
        s.y.push_back(std::pow(1.0 + 3.0 * t / alpha, -alpha) * (model ? 1.0 : 1.0 + 0.03 * std::sin(9.0 * t)));
      }
      chart.series.push_back(s);
    }
  }
  chart.vertical_lines = {2.5};
  return chart;
}

void BM_ChartPng(benchmark::State& state) {
  require_display(state);
  const viz::Chart chart = transmittance_chart();
  const fs::path png = out_dir() / "chart.png";
  for (auto _ : state) {
    if (!viz::save_chart_png(chart, png).written) state.SkipWithError("chart not written");
  }
}
BENCHMARK(BM_ChartPng)->Unit(benchmark::kMillisecond)->UseRealTime();

// A plain weave of n x n x n/4 voxels: yarns along x and y, undulating in z.
volume::Grid woven(int n) {
  volume::Grid grid(1.0 / n, "concentration");
  auto acc = grid.impl().grid->getAccessor();
  const int nz = n / 4;
  const double pitch = n / 6.0;
  const double radius = 0.35 * pitch;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double yc = (std::floor(j / pitch) + 0.5) * pitch;
        const double xc = (std::floor(i / pitch) + 0.5) * pitch;
        const double zx = nz / 2.0 + 0.22 * nz * std::cos(M_PI * i / pitch) * (int(j / pitch) % 2 ? 1 : -1);
        const double zy = nz / 2.0 - 0.22 * nz * std::cos(M_PI * j / pitch) * (int(i / pitch) % 2 ? 1 : -1);
        const double d = std::min(std::hypot(j - yc, 1.6 * (k - zx)), std::hypot(i - xc, 1.6 * (k - zy)));
        if (d < radius) acc.setValue(openvdb::Coord(i, j, k), static_cast<float>(0.6 + 0.4 * (1.0 - d / radius)));
      }
    }
  }
  return grid;
}

void BM_VolumeViewPng(benchmark::State& state) {
  require_display(state);
  const volume::Grid grid = woven(static_cast<int>(state.range(0)));
  viz::VolumeView view;
  view.title = "woven slab";
  view.arrows = {{{1, 0, 0}, {220, 40, 40}, "x"}, {{0, 1, 0}, {40, 160, 40}, "y"}, {{0, 0, -1}, {40, 80, 220}, "z"}};
  const fs::path png = out_dir() / "volume.png";
  for (auto _ : state) {
    if (!viz::save_volume_png(grid, view, png).written) state.SkipWithError("view not written");
  }
  state.counters["voxels"] = static_cast<double>(grid.active_voxel_count());
}
// 128: shown at full resolution; 512 (~6.5 M active voxels in a 512x512x128 box): averaged down.
BENCHMARK(BM_VolumeViewPng)->Arg(128)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
