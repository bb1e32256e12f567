// Benchmark of overlapping Allan deviation with octave taus, noise identification and Greenhall
// edf included (goals, issue 37: 10^6 samples <= 5 ms, 10^7 <= 60 ms; docs/BENCHMARKS.md).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "compensation/allan.hpp"

namespace {

using station::compensation::overlapping_adev;
using station::compensation::tau_factors;
using station::compensation::TauSpacing;

void BM_OverlappingAdevOctave(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::mt19937_64 rng(1);
  std::normal_distribution<double> dist(15.0, 0.5);
  std::vector<double> rate_dph(n);
  for (double& y : rate_dph) y = dist(rng);
  const auto ms = tau_factors(n, TauSpacing::octave);
  // The thread's first curve of this length takes its working memory fresh (12 bytes a sample,
  // kept for the next: allan.cpp, curve_scratch); a one-off cost docs/BENCHMARKS.md gives apart.
  benchmark::DoNotOptimize(overlapping_adev(rate_dph, 1.0, ms).data());
  for (auto _ : state) {
    auto curve = overlapping_adev(rate_dph, 1.0, ms);
    benchmark::DoNotOptimize(curve.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_OverlappingAdevOctave)->Arg(1'000'000)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

}  // namespace
