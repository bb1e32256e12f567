// Test and benchmark helper: 600 s bins of a gyro that follows the paper's model exactly, plus
// seeded white noise, written through the Store API (no 1 Hz samples).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station::testing_support {

/// The model a synthetic gyro follows: bias = B0 + k1 (T - 25) + k0 gradT + noise.
struct SyntheticGyro {
  double b0_dph = 0.05, k1 = 1.2e-3, k0 = 0.012;  ///< deg/h, deg/h/C, deg/h/C
  double noise_dph = 0.003;                       ///< std of a bin's white noise, deg/h
  std::uint64_t seed = 1;                         ///< the noise's seed
};

/// `n` complete bins over a -40..70 C cycle with a gradient that is not collinear with T.
inline std::vector<compensation::Bin> synthetic_bins(const SyntheticGyro& g, int n = 66) {
  std::mt19937_64 rng(g.seed);
  std::normal_distribution<double> noise(0.0, g.noise_dph);
  std::vector<compensation::Bin> bins(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double x = static_cast<double>(i) / n;
    auto& b = bins[static_cast<std::size_t>(i)];
    b.t_start_s = 600.0 * i;
    b.t_mid_s = b.t_start_s + 300.0;
    b.n = 600;
    b.temp_c = 15.0 - 55.0 * std::cos(2.0 * M_PI * x);
    b.grad_c = 0.8 * std::sin(2.0 * M_PI * x) + 0.2 * std::sin(6.0 * M_PI * x);
    b.rate_dph = g.b0_dph + g.k1 * (b.temp_c - 25.0) + g.k0 * b.grad_c + noise(rng);
    b.complete = true;
  }
  return bins;
}

/// A run of `serials` (one slot each, Earth rate 0) whose bins follow `gyros[i]`.
inline std::int64_t store_synthetic_run(Store& store, const std::vector<std::string>& serials,
                                        const std::vector<SyntheticGyro>& gyros) {
  std::vector<RunSlot> slots;
  for (std::size_t i = 0; i < serials.size(); ++i)
    slots.push_back(
        {static_cast<int>(i), static_cast<int>(i % 16) + 1, serials[i], "up", 1.5, 0.0});
  const RunInfo info{"synthetic", "", "", "test", "bench", "", std::nullopt, 0.0, {}};
  const auto run = store.create_run(info, slots);
  for (std::size_t i = 0; i < serials.size(); ++i)
    store.replace_bins(run, serials[i], synthetic_bins(gyros[i]), 0.0);
  store.finish_run(run, station::RunState::completed);
  return run;
}

}  // namespace station::testing_support
