// Leave-one-run-out cross-validation (compensation/cross_validation.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "compensation/cross_validation.hpp"

namespace sc = station::compensation;

namespace {

/// Three runs of a ramp -40..70 C with the model B = 0.1 + 2e-3 dT + 0.03 gradT plus white noise
/// of `sigma_dph` (seeded).
sc::ModelData three_runs(double sigma_dph, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_dph);
  sc::ModelData d;
  for (int run = 0; run < 3; ++run)
    for (int i = 0; i < 40; ++i) {
      const double t = -40 + 110.0 * i / 39.0;
      const double g = 0.5 * std::sin(0.3 * i + run);
      d.temp_c.push_back(t);
      d.grad_c.push_back(g);
      d.bias_dph.push_back(0.1 + 2e-3 * (t - 25) + 0.03 * g + noise(rng));
      d.t_mid_s.push_back(600.0 * i);
      d.segment.push_back(run);
    }
  return d;
}

}  // namespace

// Without noise, the model predicts a run it did not see exactly (to rounding).
TEST(CrossValidation, ExactModelPredictsHeldOutRunsToRounding) {
  const auto d = three_runs(0.0, 1);
  const auto cv = sc::leave_one_run_out(d.view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
  ASSERT_EQ(cv.runs.size(), 3u);
  EXPECT_LT(cv.pooled_rms_dph, 1e-12);
  for (const auto& h : cv.runs) EXPECT_EQ(h.bins, 40u);
}

// With white noise of sigma, a right model's held-out RMS is about sigma·sqrt(1 + p/n) and its
// in-sample RMS sigma·sqrt(1 − p/n) (p = 3 coefficients, n = 80 training bins); an over-fitted
// model (dT..dT4 and gradT: 6 coefficients) shows a larger gap between the two.
TEST(CrossValidation, AnOverfittedModelShowsAsAHeldOutErrorAboveTheInSampleOne) {
  double right_gap = 0, over_gap = 0;
  const int trials = 40;
  for (int k = 0; k < trials; ++k) {
    const auto d = three_runs(0.01, 100 + k);
    const auto right = sc::leave_one_run_out(d.view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
    const auto over = sc::leave_one_run_out(
        d.view(),
        {{sc::Term::dT, sc::Term::dT2, sc::Term::dT3, sc::Term::dT4, sc::Term::gradT}, 25.0});
    right_gap += right.pooled_rms_dph / right.in_sample_rms_dph / trials;
    over_gap += over.pooled_rms_dph / over.in_sample_rms_dph / trials;
  }
  // sqrt((1 + 3/80) / (1 - 3/120)) = 1.032 for the right model; 6 terms: ~1.07. The mean over 40
  // trials has a standard error of ~0.01.
  EXPECT_NEAR(right_gap, 1.032, 0.03);
  EXPECT_GT(over_gap, right_gap + 0.015);
}

TEST(CrossValidation, NeedsTwoRuns) {
  auto d = three_runs(0.01, 3);
  for (auto& s : d.segment) s = 0;
  EXPECT_THROW(sc::leave_one_run_out(d.view(), {{sc::Term::dT}, 25.0}), std::invalid_argument);
  d.segment.clear();
  EXPECT_THROW(sc::leave_one_run_out(d.view(), {{sc::Term::dT}, 25.0}), std::invalid_argument);
}
