// Simulated RLG: thermal lag and gradient, noise magnitudes, determinism, pulse bookkeeping.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "sim_devices/counter_board_gyro.hpp"
#include "sim_devices/counter_board_sim.hpp"

namespace sim = station::sim;

namespace {

sim::GyroConfig quiet_gyro() {
  sim::GyroConfig g;
  g.noise = {0.0, 0.0, 3600.0, 0.0};
  return g;
}

// gradT after `hours` of a ramp of rate_c_per_h from 25 C.
double grad_after_ramp(double rate_c_per_h, double hours) {
  sim::RlgGyroModel m(quiet_gyro());
  const double end_s = hours * 3600.0;
  for (double t = 1.0; t <= end_s; t += 1.0) m.step_to(t, 25.0 + rate_c_per_h * t / 3600.0);
  return m.grad_t_c();
}

}  // namespace

// Series lags air -> A (tau_h) -> B (tau_c): under a steady ramp r, B - A -> -r * tau_c. The
// transient decays as exp(-t/tau_c); after 6 h (6 tau_c) it is below 1.5 * exp(-6) = 0.4 %.
TEST(CounterBoardSim, GradientGrowsWithRampRate) {
  const double g20 = grad_after_ramp(20.0, 6.0);
  const double g10 = grad_after_ramp(10.0, 6.0);
  const double g0 = grad_after_ramp(0.0, 6.0);
  EXPECT_NEAR(g20, -20.0 / 3600.0 * 3600.0, 0.01 * 20.0);
  EXPECT_NEAR(g10, -10.0 / 3600.0 * 3600.0, 0.01 * 10.0);
  EXPECT_GT(std::abs(g20), std::abs(g10));
  EXPECT_GT(std::abs(g10), 100 * std::abs(g0));
  EXPECT_NEAR(g0, 0.0, 1e-9);
}

// With noise off the bias is exactly the model B0 + k1 dT + k2 dT^2 + k0 gradT.
TEST(CounterBoardSim, ThermalBiasFollowsTrueCoefficients) {
  sim::GyroConfig g = quiet_gyro();
  g.coefficients = {0.07, 1.2e-3, 3e-5, 0.03, 25.0};
  sim::RlgGyroModel m(g);
  for (double t = 1.0; t <= 7200.0; t += 1.0) m.step_to(t, 25.0 + 30.0 * t / 3600.0);
  const double dT = m.temp_a_c() - 25.0;
  EXPECT_GT(dT, 20.0);
  EXPECT_DOUBLE_EQ(m.thermal_bias_dph(),
                   0.07 + 1.2e-3 * dT + 3e-5 * dT * dT + 0.03 * (m.temp_b_c() - m.temp_a_c()));
}

// White rate noise at 1 Hz has sigma = 60 * ARW deg/h (IEEE 952). The sample std of n = 20000
// Gaussian samples has relative sd 1/sqrt(2n) = 0.5 %; 3 % is six of those.
TEST(CounterBoardSim, ArwGivesWhiteRateSigma) {
  sim::GyroConfig g = quiet_gyro();
  g.noise.arw_dpsh = 0.003;
  g.coefficients.B0_dph = 0.0;
  g.coefficients.k1 = g.coefficients.k2 = g.coefficients.k0 = 0.0;
  g.seed = 2024;
  sim::RlgGyroModel m(g);
  std::vector<double> rate;
  double prev = 0;
  for (int k = 1; k <= 20000; ++k) {
    m.step_to(k, 25.0);
    rate.push_back(m.true_angle_arcsec() - prev);  // arcsec per 1 s == deg/h
    prev = m.true_angle_arcsec();
  }
  const double mean = std::accumulate(rate.begin(), rate.end(), 0.0) / rate.size();
  double ss = 0;
  for (double r : rate) ss += (r - mean) * (r - mean);
  EXPECT_NEAR(std::sqrt(ss / (rate.size() - 1)), 60.0 * 0.003, 0.03 * 0.18);
}

TEST(CounterBoardSim, SameSeedSameRunDifferentSeedDifferent) {
  sim::GyroConfig g;
  g.seed = 7;
  sim::RlgGyroModel a(g), b(g);
  g.seed = 8;
  sim::RlgGyroModel c(g);
  for (double t = 0.5; t <= 100.0; t += 0.5) {
    a.step_to(t, 30.0);
    b.step_to(t, 30.0);
    c.step_to(t, 30.0);
  }
  EXPECT_EQ(a.true_angle_arcsec(), b.true_angle_arcsec());
  EXPECT_EQ(a.net_pulses(), b.net_pulses());
  EXPECT_NE(a.true_angle_arcsec(), c.true_angle_arcsec());
}

// Pulses carry the remainder: 0 <= angle - pulses * w < w at every instant.
TEST(CounterBoardSim, PulsesNeverLoseAngle) {
  sim::GyroConfig g;
  g.earth_rate_dph = -9.65;  // negative: exercises the down counter
  sim::RlgGyroModel m(g);
  for (int k = 1; k <= 3000; ++k) {
    m.step_to(k, 25.0);
    const double rem = m.true_angle_arcsec() - m.net_pulses() * g.pulse_weight_arcsec;
    ASSERT_GE(rem, -1e-6);
    ASSERT_LT(rem, g.pulse_weight_arcsec + 1e-6);
  }
  EXPECT_EQ(m.net_pulses(),
            static_cast<std::int64_t>(m.up_pulses()) - static_cast<std::int64_t>(m.down_pulses()));
  EXPECT_GT(m.down_pulses(), 0u);
}

TEST(CounterBoardSim, BoardAnswersSyncWithFourFrames) {
  sim::BoardConfig cfg;
  cfg.node = 5;
  sim::CounterBoardSim board(cfg);
  board.step_to(10.0, 25.0);
  const auto frames = board.on_sync(3);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].frame.can_id, 0x185u);
  EXPECT_EQ(frames[0].frame.data[0], 3);
  EXPECT_EQ(frames[1].frame.can_id, 0x285u);
  EXPECT_EQ(frames[2].frame.can_id, 0x385u);
  EXPECT_EQ(frames[3].frame.can_id, 0x485u);
  board.drop_next_frames(2);
  EXPECT_EQ(board.on_sync(4).size(), 2u);
  board.set_answering(false);
  EXPECT_TRUE(board.on_sync(5).empty());
}
