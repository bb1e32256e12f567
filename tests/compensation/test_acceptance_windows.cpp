// A window's mean count rate and its error (compensation/acceptance_windows.hpp) on the
// counter's own arithmetic: whole pulses of a random-walk angle, the fraction carried from one
// second to the next (as sim_devices/counter_board_gyro.cpp counts them).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "compensation/acceptance_windows.hpp"

namespace {

namespace comp = station::compensation;

// An RLG's white rate noise in pulses: 0.003 deg/sqrt(h) is 0.18 deg/h in 1 s, 0.12 pulse/s at
// 1.5" (IEEE 952 Annex C: N deg/sqrt(h) = 60 N deg/h/sqrt(Hz)).
constexpr double kWhitePps = 0.12;

struct Counted {
  std::vector<double> pps, spans_s;
  double true_pps = 0;
};

// n seconds of a gyro at `rate_pps` (plus white noise), counted in whole pulses from a random
// phase: pps_i = floor(A_i) - floor(A_(i-1)).
Counted count(std::mt19937_64& rng, double rate_pps, int n) {
  std::normal_distribution<double> white(0.0, kWhitePps);
  std::uniform_real_distribution<double> phase(0.0, 1.0);
  Counted c;
  c.true_pps = rate_pps;
  double angle = phase(rng), last = std::floor(angle);
  for (int i = 0; i < n; ++i) {
    angle += rate_pps + white(rng);
    c.pps.push_back(std::floor(angle) - last);
    c.spans_s.push_back(1.0);
    last = std::floor(angle);
  }
  return c;
}

comp::WindowSeries series(const Counted& c) {
  return {c.pps, c.spans_s};
}

TEST(AcceptanceWindows, QuantizationIsTwoEndsRounding) {
  // Two uniform errors of one pulse at the ends: sd 1/sqrt(6) pulse over the window (GUM 4.3.7).
  EXPECT_NEAR(comp::mean_quantization_pps(60.0), 1.0 / (60.0 * std::sqrt(6.0)), 1e-15);
  EXPECT_EQ(comp::mean_quantization_pps(0.0), 0.0);
  EXPECT_EQ(comp::mean_quantization_pps(-1.0), 0.0);
}

TEST(AcceptanceWindows, MeanIsTheCountOverTheSpan) {
  // 10 pulses in 2 s, then 3 in 1 s: 13 pulses in 3 s, not the mean of 5 and 3.
  const std::vector<double> pps{5.0, 3.0}, spans{2.0, 1.0};
  const auto m = comp::window_mean({pps, spans}, 0.0, 1.0);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->mean, 13.0 / 3.0, 1e-12);
  EXPECT_NEAR(m->se, comp::mean_quantization_pps(3.0), 1e-15);  // no white noise: rounding only
  EXPECT_FALSE(comp::window_mean({}, 0.0, 1.0));
}

TEST(AcceptanceWindows, NothingToPoolIsNoEstimate) {
  const std::vector<double> one{1.0}, span{1.0};
  const std::vector<comp::WindowSeries> w{{one, span}};
  EXPECT_FALSE(comp::pooled_white_density(w, 1.0));
  EXPECT_FALSE(comp::pooled_white_density({}, 1.0));
}

TEST(AcceptanceWindows, ANoiseFreeRateIsRoundingOnly) {
  // Whole pulses of a steady rate: the batches differ only by their ends' rounding, which the
  // estimate takes out; what is left is 0 within its own scatter, far below the gyro's 0.0144.
  std::mt19937_64 rng(7);
  std::vector<Counted> c;
  for (double rate : {6.43, 2406.627, 240020.81}) {
    Counted k;
    double angle = 0.37, last = 0;
    for (int i = 0; i < 300; ++i) {
      angle += rate;
      k.pps.push_back(std::floor(angle) - last), k.spans_s.push_back(1.0);
      last = std::floor(angle);
    }
    c.push_back(k);
  }
  std::vector<comp::WindowSeries> w;
  for (const auto& k : c) w.push_back(series(k));
  const auto s = comp::pooled_white_density(w, 1.0);
  ASSERT_TRUE(s);
  EXPECT_LT(*s, 0.2 * kWhitePps * kWhitePps);
}

// The shipped session's windows: a ladder's six dwells of 59 s at rates with random fractions,
// four positions of 300 s near 6.4 pulse/s; 600 draws of 10 windows.
TEST(AcceptanceWindows, PooledErrorsCoverTheCountedRateAsStated) {
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> frac(0.0, 1.0);
  constexpr int kDraws = 600;
  double s_sum = 0;
  int n = 0, in1 = 0, in2 = 0;
  for (int d = 0; d < kDraws; ++d) {
    std::vector<Counted> c;
    for (double r : {2406.0, -2394.0, 24008.0, -23995.0, 240020.0, -240001.0})
      c.push_back(count(rng, r + frac(rng), 59));
    for (int k = 0; k < 4; ++k) c.push_back(count(rng, 6.4 + 0.05 * frac(rng), 300));
    std::vector<comp::WindowSeries> w;
    for (const auto& k : c) w.push_back(series(k));
    const auto s = comp::pooled_white_density(w, 1.0);
    ASSERT_TRUE(s);
    s_sum += *s;
    for (const auto& k : c) {
      const auto m = comp::window_mean(series(k), *s, 1.0);
      ASSERT_TRUE(m);
      const double z = std::abs(m->mean - k.true_pps) / m->se;
      ++n, in1 += z <= 1, in2 += z <= 2;
    }
  }
  // S unbiased: its relative sd per draw was 0.26 in a simulation of 1200 draws, so the mean of
  // 600 is within 3 x 0.26 / sqrt(600) = 0.032 of the truth.
  const double s_mean = s_sum / kDraws, s_true = kWhitePps * kWhitePps;
  EXPECT_NEAR(s_mean / s_true, 1.0, 0.032);
  // Coverage: 6000 z, but the ten of a draw share one S, so the binomial sd is taken over the
  // 600 draws (the larger, conservative count of independent units) and the band is 3 sd.
  const double c1 = double(in1) / n, c2 = double(in2) / n;
  std::printf("[coverage] S/S_true %.3f  +-1 SE %.3f  +-2 SE %.3f  (%d)\n", s_mean / s_true, c1, c2,
              n);
  EXPECT_NEAR(c1, 0.683, 3 * std::sqrt(0.683 * 0.317 / kDraws));
  EXPECT_NEAR(c2, 0.954, 3 * std::sqrt(0.954 * 0.046 / kDraws));
}

}  // namespace
