// Lack-of-fit and collinearity diagnostics (compensation/fit_diagnostics.hpp), on a simulated
// thermal cycle: 78 bins of 600 s over 13 h, T from -40 to +70 C and back, a gradient that
// follows the heating rate (the paper's hysteresis) plus its own slow variation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "compensation/fit_diagnostics.hpp"

namespace sc = station::compensation;

namespace {

struct Truth {
  double b0 = 0.1, k1 = 2e-3, k0 = 0.03, k2 = 0.0, sigma = 0.003;
};

sc::ModelData cycle(const Truth& t, unsigned seed, double grad_noise_c = 0.3) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> white(0.0, t.sigma);
  const double period_s = 13 * 3600.0;
  sc::ModelData d;
  for (int i = 0; i < 78; ++i) {
    const double ts = 600.0 * i + 300.0;
    const double w = 2 * std::numbers::pi / period_s;
    const double temp = 15 - 55 * std::cos(w * ts);
    const double dtdt = 55 * w * std::sin(w * ts) * 3600.0;  // C/h
    const double grad = 0.02 * dtdt + grad_noise_c * std::sin(0.37 * i);
    const double dT = temp - 25;
    d.t_mid_s.push_back(ts);
    d.temp_c.push_back(temp);
    d.grad_c.push_back(grad);
    d.dtdt_c_per_h.push_back(dtdt);
    d.bias_dph.push_back(t.b0 + t.k1 * dT + t.k2 * dT * dT + t.k0 * grad + white(rng));
  }
  return d;
}

bool warns_missing(const sc::FitResult& f) {
  for (const auto& w : f.warnings)
    if (w.find("missing term") != std::string::npos) return true;
  return false;
}

double coefficient(const sc::FitResult& f, const std::string& name) {
  for (std::size_t i = 0; i < f.names.size(); ++i)
    if (f.names[i] == name) return f.coefficients[i];
  return NAN;
}

}  // namespace

// A true k2 dT^2 the dT + gradT model lacks: the check names dT2, and with it k0 is back near
// its truth while the fit without it is off.
TEST(FitDiagnostics, AMissingQuadraticTermIsNamedWithWhatK0Becomes) {
  Truth t;
  t.k2 = 1e-5;  // 0.03 deg/h at the ends of the cycle, ten times the bin noise
  const auto d = cycle(t, 7);
  const auto fit = sc::fit_model(d.view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
  ASSERT_TRUE(warns_missing(fit));
  std::string w;
  for (const auto& x : fit.warnings)
    if (x.find("missing term") != std::string::npos) w = x;
  EXPECT_NE(w.find("missing term dT2"), std::string::npos) << w;
  EXPECT_NE(w.find("k0 "), std::string::npos) << w;
  const auto it = std::find_if(fit.candidates.begin(), fit.candidates.end(),
                               [](const auto& c) { return c.option == "dT2"; });
  ASSERT_NE(it, fit.candidates.end());
  EXPECT_TRUE(it->significant);
  EXPECT_NEAR(it->value, 1e-5, 4 * it->std_error);
  // The extended model's k0 (coefficients B0, k1, k0, then k2) against the truth.
  const auto with = sc::fit_model(d.view(), {{sc::Term::dT, sc::Term::gradT, sc::Term::dT2}, 25.0});
  EXPECT_NEAR(it->coefficients[2], coefficient(with, "k0"), 1e-12);
  EXPECT_NEAR(coefficient(with, "k0"), t.k0, 4 * with.std_errors[2]);
  EXPECT_FALSE(warns_missing(with)) << "the full model: nothing missing";
}

// With the right model and white noise, a missing-term warning is a false alarm: the test holds
// its 1 % family-wise level (binomial: 200 fits at p = 0.01 give 2 +- 1.4; 8 is 4 sd out).
TEST(FitDiagnostics, FalseAlarmsUnderWhiteNoiseStayNearOnePercent) {
  int alarms = 0;
  for (unsigned seed = 0; seed < 200; ++seed) {
    const auto fit =
        sc::fit_model(cycle(Truth{}, 1000 + seed).view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
    alarms += warns_missing(fit) ? 1 : 0;
    ASSERT_EQ(fit.candidates.size(), 4u);  // dT2, dT3, dTdt, gradTdT
    EXPECT_NEAR(fit.candidate_z_critical, 3.0233, 1e-4);
  }
  EXPECT_LE(alarms, 8);
}

// A gradient that is nothing but a function of temperature: the VIF of k1 and k0 explodes and
// the warning says in words that the protocol cannot separate them, and which one would.
TEST(FitDiagnostics, AGradientThatFollowsTemperatureIsSaidToBeInseparable) {
  auto d = cycle(Truth{}, 3, 0.0);
  for (std::size_t i = 0; i < d.grad_c.size(); ++i)
    d.grad_c[i] = 0.02 * (d.temp_c[i] - 15) + 0.002 * std::sin(1.7 * i);
  const auto fit = sc::fit_model(d.view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
  ASSERT_EQ(fit.vif.size(), 2u);
  EXPECT_GT(fit.vif[0], 10.0);
  EXPECT_NEAR(fit.vif[0], fit.vif[1], 1e-9 * fit.vif[0]) << "two terms: one VIF";
  bool said = false;
  for (const auto& w : fit.warnings)
    said = said || (w.find("k1 and k0 cannot be separated") != std::string::npos &&
                    w.find("ramp_10 with ramp_20") != std::string::npos);
  EXPECT_TRUE(said);
  // The paper-like cycle separates them: no such warning, VIFs near 1.
  const auto good =
      sc::fit_model(cycle(Truth{}, 3).view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
  for (const double v : good.vif) EXPECT_LT(v, 10.0);
}

// VIF against its definition 1 / (1 - R^2) of one regressor on the others, computed by hand.
TEST(FitDiagnostics, VifMatchesOneOverOneMinusRSquared) {
  const auto d = cycle(Truth{}, 5);
  const auto fit = sc::fit_model(d.view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
  double mt = 0, mg = 0;
  const auto n = static_cast<double>(d.temp_c.size());
  for (std::size_t i = 0; i < d.temp_c.size(); ++i) {
    mt += d.temp_c[i] / n;
    mg += d.grad_c[i] / n;
  }
  double stt = 0, sgg = 0, stg = 0;
  for (std::size_t i = 0; i < d.temp_c.size(); ++i) {
    stt += (d.temp_c[i] - mt) * (d.temp_c[i] - mt);
    sgg += (d.grad_c[i] - mg) * (d.grad_c[i] - mg);
    stg += (d.temp_c[i] - mt) * (d.grad_c[i] - mg);
  }
  const double vif = 1.0 / (1.0 - stg * stg / (stt * sgg));
  ASSERT_EQ(fit.vif.size(), 2u);
  EXPECT_NEAR(fit.vif[0], vif, 1e-9 * vif);
  EXPECT_NEAR(fit.vif[1], vif, 1e-9 * vif);
}
