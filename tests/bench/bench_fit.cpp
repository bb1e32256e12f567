// Benchmarks of one thermal bias fit: 5 terms on 10^4 bins, and the paper's model on a cycle.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "compensation/fit.hpp"
#include "sim_devices/sim_world.hpp"
#include "tests/calibration/paper_cycle.hpp"

namespace {

void BM_Fit5TermsOn10kBins(benchmark::State& state) {
  namespace sc = station::compensation;
  const auto n = static_cast<std::size_t>(state.range(0));
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, 0.003);
  sc::ModelData d;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i) / static_cast<double>(n);
    d.temp_c.push_back(-40.0 + 110.0 * x);
    d.grad_c.push_back(std::sin(20.0 * x));
    d.dtdt_c_per_h.push_back(10.0 + std::cos(7.0 * x));
    d.bias_dph.push_back(0.02 + 1e-3 * (d.temp_c.back() - 25.0) + 0.03 * d.grad_c.back() +
                         noise(rng));
  }
  sc::ModelSpec spec;
  spec.terms = {sc::Term::dT, sc::Term::dT2, sc::Term::gradT, sc::Term::dTdt};
  for (auto _ : state) {
    auto fit = sc::fit_model(d.view(), spec);
    benchmark::DoNotOptimize(fit.coefficients.data());
  }
}
BENCHMARK(BM_Fit5TermsOn10kBins)->Arg(10000)->Unit(benchmark::kMicrosecond);

// The paper's model (B0, k1, k0) on one simulated gyro's paper cycle (65 bins): what one fit of
// `station fit` costs, the REML error model of correlated_errors.hpp included.
void BM_FitPaperCycle(benchmark::State& state) {
  namespace sc = station::compensation;
  station::sim::GyroConfig g;
  g.coefficients = station::sim::sim_coefficients(1, 0);
  const sc::ModelData d = station::test::paper_cycle_bins(g);
  for (auto _ : state) {
    auto fit = sc::fit_model(d.view(), {});
    benchmark::DoNotOptimize(fit.std_errors.data());
  }
}
BENCHMARK(BM_FitPaperCycle)->Unit(benchmark::kMicrosecond);

}  // namespace
