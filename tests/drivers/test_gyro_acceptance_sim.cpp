// Issue 36's simulated gyro physics: it senses the table through its scale factor, its power
// follows its relay (turn-on bias, warm-up), its misalignment modulates the Earth rate with the
// table angle; with none of it configured a run is the same bits as before.
#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <vector>

#include "drivers/counters/counter_frames.hpp"
#include "drivers/gpio/gpio_bank.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "sim_devices/counter_board_sim.hpp"
#include "sim_devices/gpio_sim.hpp"
#include "sim_devices/sim_world.hpp"

namespace sim = station::sim;
namespace wire = station::drivers::counters;

namespace {

constexpr double kPi = 3.14159265358979323846;

sim::GyroConfig quiet_gyro() {
  sim::GyroConfig g;
  g.noise = {0.0, 0.0, 3600.0, 0.0};
  g.coefficients = {0.0, 0.0, 0.0, 0.0, 25.0};
  return g;
}

// Net pulses of `g` over [from_s, to_s] stepped at 1 s with air at `air_c`.
std::int64_t net_pulses_over(sim::RlgGyroModel& g, double from_s, double to_s, double air_c) {
  for (double t = g.time_s() + 1.0; t <= from_s + 1e-9; t += 1.0) g.step_to(t, air_c);
  const std::int64_t start = g.net_pulses();
  for (double t = from_s + 1.0; t <= to_s + 1e-9; t += 1.0) g.step_to(t, air_c);
  return g.net_pulses() - start;
}

struct Recorded {
  int preset, node;
  long long net;
  unsigned long long up, down, dither;
  double angle_arcsec;
};

// Recorded from the code before issue 36 (commit 8bb59b2) by the scenario of DefaultsAreTheBits
// BeforeIssue36: 3 gyros, seed 7, a chamber ramp, 1 s ticks, a 200 s jump, 0.5 s ticks.
const Recorded kBefore[] = {
    {0, 1, 2870LL, 2870ULL, 0ULL, 9000000ULL, 0x1.0d178e6d8c501p+12},
    {0, 2, 2900LL, 2900ULL, 0ULL, 9000000ULL, 0x1.0fe341cbd7e59p+12},
    {0, 3, 2879LL, 2879ULL, 0ULL, 9000000ULL, 0x1.0dfaaf54069e2p+12},
    {1, 1, 2904LL, 2904ULL, 0ULL, 9000000ULL, 0x1.1047b14de5db1p+12},
    {1, 2, 2906LL, 2906ULL, 0ULL, 9000000ULL, 0x1.10739a3f78c3bp+12},
    {1, 3, 2900LL, 2900ULL, 0ULL, 9000000ULL, 0x1.0ff450941a7a2p+12},
};

}  // namespace

// With acceptance off (the default) the gyros are the same bits as before issue 36, although the
// Earth rate now has a north part and the gyros are wired to the (resting) table.
TEST(GyroAcceptanceSim, DefaultsAreTheBitsBeforeIssue36) {
  for (int preset = 0; preset < 2; ++preset) {
    sim::SimWorldConfig c;
    c.gyros = 3;
    c.seed = 7;
    c.noise_run = static_cast<std::uint64_t>(preset);
    c.preset = preset ? sim::GyroPreset::paper : sim::GyroPreset::station;
    c.earth_rate_dph = 9.6708;
    c.earth_rate_north_dph = 11.5249;  // no part of it reaches an aligned vertical axis
    sim::SimWorld w(c);
    w.chamber().set_setpoint_c(45.0);
    w.chamber().set_ramp_c_per_min(1.0);
    w.chamber().set_run(true);
    for (int t = 1; t <= 200; ++t) w.advance_to(t);
    w.advance_to(400.0);
    for (double t = 400.5; t <= 450.0; t += 0.5) w.advance_to(t);
    for (const Recorded& r : kBefore) {
      if (r.preset != preset) continue;
      const auto& g = w.bus()->board(static_cast<std::uint8_t>(r.node)).gyro();
      EXPECT_EQ(g.net_pulses(), r.net) << preset << " " << r.node;
      EXPECT_EQ(g.up_pulses(), r.up);
      EXPECT_EQ(g.down_pulses(), r.down);
      EXPECT_EQ(g.dither_pulses(), r.dither);
      EXPECT_EQ(g.true_angle_arcsec(), r.angle_arcsec);  // the same bits
    }
  }
}

// At a steady table rate the gyro counts (1 + eps) * rate, eps the IEEE 647 terms written out
// here by hand: SF error + TC*dT + N*(5x^2-3)/2 + sign*asym/2. Within one pulse over 100 s.
TEST(GyroAcceptanceSim, SteadyTableRateGivesScaledPulses) {
  for (double rate_dps : {100.0, -100.0, 300.0}) {
    sim::GyroConfig c = quiet_gyro();
    c.thermal.initial_c = 35.0;  // dT = 10 C throughout
    c.acceptance.sf_error_ppm = 40.0;
    c.acceptance.sf_tc_ppm_per_c = 3.0;
    c.acceptance.nonlinearity_ppm = 30.0;
    c.acceptance.asymmetry_ppm = 20.0;
    c.acceptance.full_scale_dps = 300.0;
    c.table_angle_deg = [rate_dps](double t_s) { return rate_dps * t_s; };
    sim::RlgGyroModel g(c);
    const double x = rate_dps / 300.0;
    const double eps_ppm = 40.0 + 3.0 * 10.0 + 30.0 * (5 * x * x - 3) / 2 + (x > 0 ? 10.0 : -10.0);
    EXPECT_NEAR(sim::scale_factor_error_ppm(c.acceptance, rate_dps, 10.0), eps_ppm, 1e-9);
    const double expected = (1 + 1e-6 * eps_ppm) * rate_dps * 3600.0 * 100.0 / 1.5;
    EXPECT_NEAR(static_cast<double>(net_pulses_over(g, 10.0, 110.0, 35.0)), expected, 1.0)
        << rate_dps;
  }
}

// The table's unwrapped angle is its integration's: 30 s at 10 deg/s^2 to 300 deg/s, 10 s at
// rate; the track answers for any time since it was last trimmed; a rate demand beyond the
// rate-mode limit is held at it.
TEST(GyroAcceptanceSim, TableTrackIsTheIntegratedAngle) {
  sim::TurntableSim table(station::drivers::turntable_map::generic_plc(1));
  ASSERT_TRUE(table.set_mode(2));
  table.set_rate_demand_dps(300.0);
  table.step_to(40.0);
  EXPECT_NEAR(table.cumulative_angle_deg(), 4500.0 + 3000.0, 1e-6);
  EXPECT_NEAR(table.cumulative_angle_at_deg(15.0), 0.5 * 10.0 * 225.0, 1e-6);
  EXPECT_NEAR(table.cumulative_angle_at_deg(35.0), 4500.0 + 1500.0, 1e-6);
  EXPECT_NEAR(table.angle_deg(), std::fmod(7500.0, 360.0), 1e-6);
  table.forget_track_before(39.0);
  EXPECT_NEAR(table.cumulative_angle_at_deg(39.5), 4500.0 + 2850.0, 1e-6);
  table.set_rate_demand_dps(-5000.0);
  table.step_to(300.0);
  EXPECT_DOUBLE_EQ(table.rate_dps(), -1000.0);
  EXPECT_EQ(table.config().max_rate_mode_dps, 1000.0);
}

// In a world, the gyro on a table turning at 100 deg/s counts the table's angle through its own
// scale factor (bias and noise: a few pulses of ~1e6).
TEST(GyroAcceptanceSim, WorldGyroSensesTheTable) {
  sim::SimWorldConfig c;
  c.gyros = 1;
  sim::AcceptanceTruth a;
  a.sf_error_ppm = 50.0;
  c.acceptance_by_node[1] = a;
  sim::SimWorld w(c);
  ASSERT_TRUE(w.turntable().set_mode(2));
  w.turntable().set_rate_demand_dps(100.0);
  for (int t = 1; t <= 20; ++t) w.advance_to(t);  // 10 s to reach the rate
  const auto& g = w.bus()->board(1).gyro();
  const std::int64_t start = g.net_pulses();
  const double angle0 = w.turntable().cumulative_angle_deg();
  for (int t = 21; t <= 120; ++t) w.advance_to(t);
  const double turned_deg = w.turntable().cumulative_angle_deg() - angle0;
  EXPECT_NEAR(turned_deg, 100.0 * 100.0, 1e-6);
  EXPECT_NEAR(static_cast<double>(g.net_pulses() - start), (1 + 50e-6) * turned_deg * 3600 / 1.5,
              20.0);
}

// On the wire at 300 deg/s: 720,000 pulses a second plus dither through the 32-bit counters
// across their wrap; the unsigned deltas give the net angle to a pulse.
TEST(GyroAcceptanceSim, CountersCarry300DegPerSecondAcrossTheWrap) {
  sim::BoardConfig b;
  b.gyro = quiet_gyro();
  b.gyro.table_angle_deg = [](double t_s) { return 300.0 * t_s; };
  b.initial_up = UINT32_MAX - 100000;
  sim::CounterBoardSim board(b);
  std::uint32_t up_prev = board.up_count(), down_prev = board.down_count();
  for (int t = 1; t <= 10; ++t) {
    board.step_to(t, 25.0);
    const std::uint32_t up = board.up_count(), down = board.down_count();
    const auto net = static_cast<std::int64_t>(static_cast<std::uint32_t>(up - up_prev)) -
                     static_cast<std::int64_t>(static_cast<std::uint32_t>(down - down_prev));
    EXPECT_NEAR(static_cast<double>(net), 720000.0, 1.0) << t;
    EXPECT_EQ(static_cast<std::uint32_t>(down - down_prev), 20000u);  // dither only
    up_prev = up;
    down_prev = down;
  }
}

// An unpowered gyro: the board answers as usual, STATUS flags laser and dither faults, COUNTS
// stand still, TEMPS still read, DISCHARGE 0/0 uA.
TEST(GyroAcceptanceSim, UnpoweredGyroOnTheWire) {
  sim::BoardConfig b;
  b.gyro = quiet_gyro();
  b.gyro.earth_rate_dph = 10.0;
  sim::CounterBoardSim board(b);
  board.step_to(10.0, 25.0);
  board.set_powered(false);
  const std::uint32_t up = board.up_count(), down = board.down_count();
  board.step_to(20.0, 30.0);
  const auto records = board.on_sync(5);
  ASSERT_EQ(records.size(), 4u);
  const auto st = wire::decode_status(records[0].frame).value();
  EXPECT_EQ(st.flags, wire::kFlagLaserFault | wire::kFlagDitherFault);
  const auto counts = wire::decode_counts(records[1].frame).value();
  EXPECT_EQ(counts.up, up);
  EXPECT_EQ(counts.down, down);
  const auto temps = wire::decode_temps(records[2].frame).value();
  EXPECT_GT(temps.centi_c[0], 2500);  // the housing warms towards 30 C
  const auto discharge = wire::decode_discharge(records[3].frame).value();
  EXPECT_EQ(discharge.leg_ua, (std::array<std::uint32_t, 2>{0, 0}));
  board.set_powered(true);
  board.step_to(30.0, 30.0);
  EXPECT_EQ(wire::decode_status(board.on_sync(6)[0].frame).value().flags, 0);
  EXPECT_GT(board.up_count(), up + 20000u * 10);  // dither and the Earth rate again
}

namespace {

// Mean rate of gyro `node` over (from_s, to_s] of world time, from its net pulses, deg/h.
double world_rate_dph(sim::SimWorld& w, std::uint8_t node, double from_s, double to_s) {
  for (double t = w.now_s() + 1.0; t <= from_s + 1e-9; t += 1.0) w.advance_to(t);
  const std::int64_t start = w.bus()->board(node).gyro().net_pulses();
  for (double t = from_s + 1.0; t <= to_s + 1e-9; t += 1.0) w.advance_to(t);
  return static_cast<double>(w.bus()->board(node).gyro().net_pulses() - start) * 1.5 /
         (to_s - from_s);
}

}  // namespace

// Slot 1's relay off: no pulses; on again: a new turn-on bias and the warm-up A*exp(-t/tau) from
// the power-up. Slot 2 has no relay (nobody claimed its line): always powered, one power-up.
// Windows of 100 s: noise and quantisation ~0.03 deg/h against turn-on sigma 1 and warm-up 3.
TEST(GyroAcceptanceSim, RelayPowerCycleGivesNewTurnOnBiasAndWarmUp) {
  namespace gpio = station::drivers::gpio;
  sim::SimWorldConfig c;
  c.gyros = 2;
  c.relay_power = true;
  sim::AcceptanceTruth a;
  a.turn_on_sigma_dph = 1.0;
  a.warmup_amplitude_dph = 3.0;
  a.warmup_tau_s = 60.0;
  c.acceptance_by_node = {{1, a}, {2, a}};
  sim::SimWorld w(c);
  sim::GpioSimBank bank(gpio::make_gpio_config({{gpio::roles::relay(1), "GYRO_PWR1"}}),
                        w.gpio_chips());
  ASSERT_TRUE(bank.open());  // the relay at its safe level: off
  EXPECT_FALSE(w.gyro_powered(1));
  ASSERT_TRUE(bank.write(gpio::roles::relay(1), true));
  const double before_dph = world_rate_dph(w, 1, 500.0, 600.0);
  ASSERT_TRUE(bank.write(gpio::roles::relay(1), false));
  const std::int64_t off_pulses = w.bus()->board(1).gyro().net_pulses();
  EXPECT_NE(world_rate_dph(w, 2, 600.0, 700.0), 0.0);
  EXPECT_EQ(w.bus()->board(1).gyro().net_pulses(), off_pulses);
  ASSERT_TRUE(bank.write(gpio::roles::relay(1), true));
  const double warm_dph = world_rate_dph(w, 1, 700.0, 760.0);
  const double after_dph = world_rate_dph(w, 1, 1200.0, 1300.0);
  const auto ups = w.power_ups(1);
  ASSERT_EQ(ups.size(), 2u);
  EXPECT_NEAR(ups[1].t_s, 700.0, 1e-6);
  EXPECT_NEAR(after_dph - before_dph, ups[1].turn_on_bias_dph - ups[0].turn_on_bias_dph, 0.1);
  EXPECT_GT(std::fabs(ups[1].turn_on_bias_dph - ups[0].turn_on_bias_dph), 1e-3);
  // The mean of 3 exp(-t/60) over the first 60 s: 3 (1 - e^-1).
  EXPECT_NEAR(warm_dph - after_dph, 3.0 * (1.0 - std::exp(-1.0)), 0.1);
  EXPECT_EQ(w.power_ups(2).size(), 1u);
  EXPECT_TRUE(w.gyro_powered(2));
}

// A vertical input axis tilted d towards table angle theta0 sees up*cos(d) + north*sin(d)*
// cos(theta - theta0); a horizontal one pointing north at table angle psi and raised d sees
// north*cos(d)*cos(theta - psi) + up*sin(d). Over 3000 s: quantisation 5e-4 deg/h.
TEST(GyroAcceptanceSim, MisalignmentModulatesEarthRateWithTableAngle) {
  const double up = 9.6708, north = 11.5249, d = 2e-3;  // W sin(40 deg), W cos(40 deg)
  sim::GyroConfig c = quiet_gyro();
  c.earth_rate_dph = up;
  c.earth_rate_north_dph = north;
  c.acceptance.misalignment_rad = d;
  c.acceptance.misalignment_azimuth_deg = 30.0;
  c.acceptance.north_at_table_deg = 90.0;
  for (auto axis : {sim::InputAxis::vertical, sim::InputAxis::horizontal}) {
    for (double theta : {0.0, 30.0, 120.0, 210.0}) {
      c.acceptance.input_axis = axis;
      c.table_angle_deg = [theta](double) { return theta; };
      sim::RlgGyroModel g(c);
      const double expected =
          axis == sim::InputAxis::vertical
              ? up * std::cos(d) + north * std::sin(d) * std::cos((theta - 30.0) * kPi / 180)
              : north * std::cos(d) * std::cos((theta - 90.0) * kPi / 180) + up * std::sin(d);
      const double rate = static_cast<double>(net_pulses_over(g, 0.0, 3000.0, 25.0)) * 1.5 / 3000;
      EXPECT_NEAR(rate, expected, 1e-3) << theta;
    }
  }
}

// acceptance_truth gives each preset gyro distinct values in the documented ranges, readable per
// slot, and leaves the thermal truth as it was.
TEST(GyroAcceptanceSim, SeededTruthPerSlot) {
  sim::SimWorldConfig c;
  c.gyros = 4;
  c.acceptance_truth = true;
  sim::SimWorld w(c);
  for (std::uint8_t n = 1; n <= 4; ++n) {
    const auto& a = w.acceptance_truth(n);
    EXPECT_GE(std::fabs(a.sf_error_ppm), 10.0);
    EXPECT_LE(std::fabs(a.sf_error_ppm), 60.0);
    EXPECT_GE(std::fabs(a.sf_tc_ppm_per_c), 1.0);
    EXPECT_LE(std::fabs(a.sf_tc_ppm_per_c), 5.0);
    EXPECT_LE(std::fabs(a.nonlinearity_ppm), 50.0);
    EXPECT_LE(std::fabs(a.asymmetry_ppm), 30.0);
    EXPECT_NEAR(a.turn_on_sigma_dph, 0.005, 0.0011);
    EXPECT_NEAR(std::fabs(a.warmup_amplitude_dph), 0.02, 0.0041);
    EXPECT_GE(a.misalignment_rad, 0.5e-3);
    EXPECT_LE(a.misalignment_rad, 2e-3);
    EXPECT_EQ(w.gyros()[n - 1].truth.B0_dph, sim::sim_coefficients(1, n - 1).B0_dph);
    if (n > 1) {
      EXPECT_NE(a.sf_error_ppm, w.acceptance_truth(1).sf_error_ppm);
    }
  }
  EXPECT_THROW(w.acceptance_truth(5), std::invalid_argument);
}
