// The IEEE 952 noise terms fitted over the whole Allan-variance curve (allan.hpp,
// fit_noise_terms).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "compensation/allan.hpp"

namespace sc = station::compensation;

namespace {

// An exact curve of the four terms (IEEE 952 Table C.2, deg/h and s) at octave taus, each point
// given 100 edf.
std::vector<sc::AdevPoint> exact_curve(double q, double n, double b, double k) {
  std::vector<sc::AdevPoint> c;
  for (double tau = 1; tau <= 65536; tau *= 2) {
    const double var = 3 * q * q / (tau * tau) + 3600 * n * n / tau +
                       2 * std::numbers::ln2 / std::numbers::pi * b * b + k * k * tau / 10800;
    sc::AdevPoint p;
    p.tau_s = tau;
    p.adev = std::sqrt(var);
    p.edf = 100;
    c.push_back(p);
  }
  return c;
}

}  // namespace

TEST(NoiseFit, RecoversTheFourTermsOfAnExactCurve) {
  const auto t = sc::fit_noise_terms(exact_curve(0.5, 0.002, 0.01, 0.05));
  ASSERT_TRUE(t.quantization_arcsec && t.angle_random_walk_deg_rth && t.bias_instability_dph &&
              t.rate_random_walk_dph_rth);
  EXPECT_NEAR(*t.quantization_arcsec, 0.5, 1e-9);
  EXPECT_NEAR(*t.angle_random_walk_deg_rth, 0.002, 1e-12);
  EXPECT_NEAR(*t.bias_instability_dph, 0.01, 1e-11);
  EXPECT_NEAR(*t.rate_random_walk_dph_rth, 0.05, 1e-10);
  EXPECT_NEAR(*t.fit_chi2_per_dof, 0.0, 1e-12);
  // The model the fit draws goes through the points.
  for (const auto& p : exact_curve(0.5, 0.002, 0.01, 0.05))
    EXPECT_NEAR(sc::noise_model_adev(t, p.tau_s) / p.adev, 1.0, 1e-9);
  // An absent term stays absent (its square is held at zero, not negative).
  const auto arw = sc::fit_noise_terms(exact_curve(0, 0.002, 0, 0));
  EXPECT_TRUE(arw.angle_random_walk_deg_rth);
  EXPECT_FALSE(arw.quantization_arcsec);
  EXPECT_FALSE(arw.rate_random_walk_dph_rth);
}

// White rate noise of 0.06 deg/h at 1 Hz is an angle random walk N = 0.06 / 60 = 1e-3 deg/sqrt(h):
// the fit finds it within 3 of its standard errors on an octave and on a decade grid, and the two
// grids agree within their combined uncertainty (the tangent method read B on one grid only).
TEST(NoiseFit, AngleRandomWalkOfWhiteNoiseDoesNotDependOnTheTauGrid) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> white(0.0, 0.06);
  std::vector<double> y(200000);
  for (auto& v : y) v = white(rng);
  const auto oct = sc::tau_factors(y.size(), sc::TauSpacing::octave);
  const auto dec = sc::tau_factors(y.size(), sc::TauSpacing::decade);
  const auto a = sc::fit_noise_terms(sc::overlapping_adev(y, 1.0, oct));
  const auto b = sc::fit_noise_terms(sc::overlapping_adev(y, 1.0, dec));
  ASSERT_TRUE(a.angle_random_walk_deg_rth && b.angle_random_walk_deg_rth);
  EXPECT_NEAR(*a.angle_random_walk_deg_rth, 1e-3, 3 * *a.angle_random_walk_se);
  EXPECT_NEAR(*b.angle_random_walk_deg_rth, 1e-3, 3 * *b.angle_random_walk_se);
  EXPECT_LT(*a.angle_random_walk_se, 2e-5);  // 200,000 samples: a tight estimate
  const double se = std::hypot(*a.angle_random_walk_se, *b.angle_random_walk_se);
  EXPECT_NEAR(*a.angle_random_walk_deg_rth, *b.angle_random_walk_deg_rth, 3 * se);
}
