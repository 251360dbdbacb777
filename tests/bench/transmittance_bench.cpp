// ns per T(t) evaluation and per sample, per law and sampler. Run:
//   build/<preset>/tests/bench/bench_transmittance --benchmark_min_time=0.2
#include <cmath>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "weft/core/rng.h"
#include "weft/transmittance/derived.h"
#include "weft/transmittance/erlang.h"
#include "weft/transmittance/exponential.h"
#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_path.h"
#include "weft/transmittance/linear.h"
#include "weft/transmittance/tabulated.h"

namespace tr = weft::transmittance;

namespace {

std::shared_ptr<const tr::Law> gamma_table() {
  const tr::GammaConcentration reference(1.0, 0.7);
  std::vector<double> t{0.0};
  std::vector<double> value{1.0};
  for (int i = 1; i < 256; ++i) {
    t.push_back(1e4 * std::pow(1e-5, 1.0 - i / 255.0));
    value.push_back(reference.transmittance(t.back()));
  }
  return std::make_shared<tr::Tabulated>(t, value);
}

std::shared_ptr<const tr::Law> make(int id) {
  switch (id) {
    case 0:
      return std::make_shared<tr::Exponential>(1.0);
    case 1:
      return std::make_shared<tr::GammaConcentration>(1.0, 0.5);
    case 2:
      return std::make_shared<tr::Linear>(1.0);
    case 3:
      return std::make_shared<tr::GammaPath>(0.5, 1.0, tr::GammaSampler::marsaglia_tsang);
    case 4:
      return std::make_shared<tr::GammaPath>(4.0, 1.0, tr::GammaSampler::marsaglia_tsang);
    case 5:
      return std::make_shared<tr::GammaPath>(0.5, 1.0, tr::GammaSampler::inversion);
    case 6:
      return std::make_shared<tr::GammaPath>(4.0, 1.0, tr::GammaSampler::inversion);
    case 7:
      return std::make_shared<tr::Erlang>(2.0, 1.0);
    case 8:
      return std::make_shared<tr::ErlangMixture>(2.0, 1.0);
    case 9:
      return gamma_table();
    case 10:
      return std::make_shared<tr::SourceFromScatterer>(std::make_shared<tr::GammaPath>(2.0, 1.0));
    default:
      return nullptr;
  }
}

const char* kNames[] = {"exponential",          "gamma(a=0.5)",          "linear",
                        "gamma-path(k=0.5,MT)", "gamma-path(k=4,MT)",    "gamma-path(k=0.5,inv)",
                        "gamma-path(k=4,inv)",  "erlang(k=2)",           "erlang-source(k=2)",
                        "tabulated(256)",       "derived-source(gp k=2)"};

void transmittance(benchmark::State& state) {
  const auto law = make(static_cast<int>(state.range(0)));
  state.SetLabel(kNames[state.range(0)]);
  weft::Pcg32 rng = weft::stream_for(1, 0);
  // Distances spread over the law's scale, precomputed so the loop times T alone.
  std::vector<double> ts(1024);
  for (auto& t : ts) t = 3.0 * rng.uniform();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(law->transmittance(ts[i++ & 1023U]));
  }
  state.SetItemsProcessed(state.iterations());
}

void sample(benchmark::State& state) {
  const auto law = make(static_cast<int>(state.range(0)));
  state.SetLabel(kNames[state.range(0)]);
  weft::Pcg32 rng = weft::stream_for(2, 0);
  for (auto _ : state) benchmark::DoNotOptimize(law->sample(rng));
  state.SetItemsProcessed(state.iterations());
}

void sample_proportional_to_transmittance(benchmark::State& state) {
  const tr::GammaConcentration law(1.0, 2.0);
  weft::Pcg32 rng = weft::stream_for(3, 0);
  for (auto _ : state) benchmark::DoNotOptimize(law.sample_proportional_to_transmittance(rng));
  state.SetItemsProcessed(state.iterations());
}

}  // namespace

BENCHMARK(transmittance)->DenseRange(0, 10);
BENCHMARK(sample)->DenseRange(0, 10);
BENCHMARK(sample_proportional_to_transmittance);
