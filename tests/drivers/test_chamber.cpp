// ModbusChamber against ChamberSim over TCP and RTU-on-pty: state, commands, ramp, faults.
#include <gtest/gtest.h>

#include <cmath>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/modbus/map_overrides.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;
using station::drivers::ChamberCommand;
using station::drivers::ChamberMode;
using station::drivers::ErrorKind;
using station::drivers::ModbusChamber;
using station::sim::ChamberSim;
using station::sim::ModbusServer;

namespace {

// One simulated chamber served over TCP, with its driver.
struct Rig {
  explicit Rig(mb::RegisterMap m, station::sim::ChamberSimConfig cfg = {})
      : map(std::move(m)), sim(map, cfg), server(sim) {
    server.start_tcp();
    chamber =
        std::make_unique<ModbusChamber>("chamber", mb::parse_endpoint(server.endpoint()), map, 0.5);
  }
  mb::RegisterMap map;
  ChamberSim sim;
  ModbusServer server;
  std::unique_ptr<ModbusChamber> chamber;
};

}  // namespace

TEST(ModbusChamber, ReadsInitialStateFromWatlowF4Map) {
  Rig rig(cm::generic_plc());
  ASSERT_TRUE(rig.chamber->connect());
  auto s = rig.chamber->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_DOUBLE_EQ(s.value().air_c, 25.0);
  EXPECT_DOUBLE_EQ(s.value().product_c, 25.0);
  EXPECT_EQ(s.value().mode, ChamberMode::constant);
  EXPECT_TRUE(s.value().run_enabled);
  EXPECT_FALSE(s.value().alarms.any());
}

// Ramp -40 C at 1 C/min from 25 C. The effective setpoint after t = 1800 s is 25 - 30 = -5 C.
// Air is a first-order lag (tau) on that ramp (rate r = 1/60 C/s): the analytic solution is
// air(t) = 25 - r t + r tau (1 - e^{-t/tau}), i.e. -5 + 2.0 (1 - e^{-15}) = -3.0 C for tau = 120 s.
// Tolerance: register resolution 0.05 C plus the discretisation error r*dt/2 < 0.001 C.
TEST(ModbusChamber, RampFollowsFirstOrderModelOverSimulatedTime) {
  Rig rig(cm::generic_plc());
  rig.chamber->set_readback_every(1);  // mode and ramp on every read (they are what is checked)
  ASSERT_TRUE(rig.chamber->command({.setpoint_c = -40.0, .ramp_c_per_min = 1.0}));
  rig.sim.step_to(1800.0);
  auto s = rig.chamber->read();
  ASSERT_TRUE(s) << s.error().message;
  const double r = 1.0 / 60.0, tau = 120.0, t = 1800.0;
  double expected_air = 25.0 - r * t + r * tau * (1.0 - std::exp(-t / tau));
  EXPECT_NEAR(s.value().air_c, expected_air, 0.06);
  EXPECT_NEAR(rig.sim.effective_setpoint_c(), -5.0, 1e-6);
  EXPECT_EQ(s.value().mode, ChamberMode::ramping);
  EXPECT_DOUBLE_EQ(s.value().setpoint_c, -40.0);
  EXPECT_DOUBLE_EQ(s.value().ramp_c_per_min, 1.0);
  // The product lags the air while cooling.
  EXPECT_GT(s.value().product_c, s.value().air_c);
  // At t = 65 min the ramp ends at -40; 10 tau later air has settled on it: constant mode.
  rig.sim.step_to(65 * 60.0 + 10 * tau);
  auto end = rig.chamber->read();
  ASSERT_TRUE(end);
  EXPECT_NEAR(end.value().air_c, -40.0, 0.06);
  EXPECT_EQ(end.value().mode, ChamberMode::constant);
}

// A step (ramp 0) is limited by the cooling capacity: 2 C/min, so 10 min after a step from 25 to
// -40 the air is at most 20 C lower, and the deviation alarm is set (|air - sp| > 5 C).
TEST(ModbusChamber, StepIsRateLimitedByCoolingCapacity) {
  Rig rig(cm::generic_plc());
  ASSERT_TRUE(rig.chamber->command({.setpoint_c = -40.0, .ramp_c_per_min = 0.0}));
  rig.sim.step_to(600.0);
  auto s = rig.chamber->read();
  ASSERT_TRUE(s);
  EXPECT_NEAR(s.value().air_c, 25.0 - 2.0 * 10.0, 0.06);
  EXPECT_TRUE(s.value().alarms.deviation);
  EXPECT_EQ(s.value().mode, ChamberMode::constant);
}

TEST(ModbusChamber, SetpointOutsideLimitRegistersIsRangeAndNotWritten) {
  station::sim::ChamberSimConfig cfg;
  cfg.setpoint_low_c = -45.0;
  cfg.setpoint_high_c = 85.0;
  Rig rig(cm::generic_plc(), cfg);
  auto r = rig.chamber->command({.setpoint_c = -50.0, .ramp_c_per_min = 2.0});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::range);
  EXPECT_NE(r.error().message.find("[-45, 85]"), std::string::npos) << r.error().message;
  auto s = rig.chamber->read();
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s.value().setpoint_c, 25.0);
  EXPECT_DOUBLE_EQ(s.value().ramp_c_per_min, 0.0);  // nothing of the command was written
  EXPECT_EQ(rig.chamber->command({.ramp_c_per_min = -1.0}).error().kind, ErrorKind::range);
  EXPECT_TRUE(rig.chamber->command({.setpoint_c = 85.0}));
}

TEST(ModbusChamber, HoldFreezesRampAndRunDisableTurnsOff) {
  Rig rig(cm::generic_plc());
  ASSERT_TRUE(rig.chamber->command({.setpoint_c = 70.0, .ramp_c_per_min = 1.0}));
  rig.sim.step_to(600.0);
  rig.sim.set_hold(true);
  rig.sim.step_to(1200.0);
  auto h = rig.chamber->read();
  ASSERT_TRUE(h);
  EXPECT_EQ(h.value().mode, ChamberMode::hold);
  EXPECT_NEAR(rig.sim.effective_setpoint_c(), 35.0, 1e-6);  // 25 + 10 min x 1 C/min, then held
  ASSERT_TRUE(rig.chamber->command({.run = false}));
  auto s = rig.chamber->read();
  ASSERT_TRUE(s);
  EXPECT_EQ(s.value().mode, ChamberMode::off);
  EXPECT_FALSE(s.value().run_enabled);
  // Output disabled: the air relaxes toward the 25 C ambient.
  double before = rig.sim.air_c();
  rig.sim.step_to(1800.0);
  EXPECT_LT(rig.sim.air_c(), before);
}

TEST(ModbusChamber, F4tFloat32CdabRoundTripsOverTheWire) {
  Rig rig(cm::generic_plc_float());
  ASSERT_TRUE(rig.chamber->command({.setpoint_c = -39.875, .ramp_c_per_min = 0.75}));
  auto s = rig.chamber->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s.value().setpoint_c, -39.875);  // exactly representable in float32
  EXPECT_EQ(s.value().ramp_c_per_min, 0.75);
  rig.sim.step_to(60.0);
  auto later = rig.chamber->read();
  ASSERT_TRUE(later);
  EXPECT_NEAR(later.value().air_c, rig.sim.air_c(), 1e-5 * 25);  // float32 precision
}

TEST(ModbusChamber, OverriddenMapIsSharedByDriverAndSimulator) {
  auto map = cm::generic_plc();
  mb::apply_overrides(map, {{.name = cm::kAir, .address = 1001, .one_based = true},
                            {.name = cm::kSetpoint, .scale = 0.01}});
  Rig rig(map);
  ASSERT_TRUE(rig.chamber->command({.setpoint_c = 12.34}));
  auto s = rig.chamber->read();
  ASSERT_TRUE(s);
  EXPECT_NEAR(s.value().setpoint_c, 12.34, 1e-9);
  EXPECT_DOUBLE_EQ(s.value().air_c, 25.0);
}

TEST(ModbusChamber, SensorBreakDoorAndHighLimitAlarms) {
  Rig rig(cm::generic_plc());
  rig.chamber->set_readback_every(1);  // the mode (read back periodically) is checked too
  rig.sim.set_air_sensor_failed(true);
  rig.sim.set_door_open(true);
  auto s = rig.chamber->read();
  ASSERT_TRUE(s);
  EXPECT_TRUE(s.value().alarms.sensor_break);
  EXPECT_TRUE(s.value().alarms.door_open);
  EXPECT_TRUE(std::isnan(s.value().air_c));  // the bogus 999.9 never reaches the caller
  EXPECT_DOUBLE_EQ(s.value().product_c, 25.0);
  rig.sim.set_air_sensor_failed(false);
  rig.sim.set_door_open(false);
  rig.sim.set_high_limit_trip(true);
  auto t = rig.chamber->read();
  ASSERT_TRUE(t);
  EXPECT_TRUE(t.value().alarms.high_limit_trip);
  EXPECT_FALSE(t.value().alarms.sensor_break);
  EXPECT_EQ(t.value().mode, ChamberMode::off);
}

TEST(ModbusChamber, InjectedFaultsGiveTypedErrorsThenRecover) {
  Rig rig(cm::generic_plc());
  rig.server.inject_timeouts(1);
  auto t = rig.chamber->read();
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().kind, ErrorKind::timeout);
  rig.server.inject_exception(MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
  auto e = rig.chamber->read();
  ASSERT_FALSE(e);
  EXPECT_EQ(e.error().kind, ErrorKind::exception);
  rig.server.inject_drop();
  auto d = rig.chamber->command({.setpoint_c = 10.0});
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().kind, ErrorKind::disconnected);
  ASSERT_TRUE(rig.chamber->command({.setpoint_c = 10.0}));
  auto ok = rig.chamber->read();
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_DOUBLE_EQ(ok.value().setpoint_c, 10.0);
}

TEST(ModbusChamber, WorksOverRtuOnAPty) {
  auto map = cm::generic_plc(7);
  ChamberSim sim(map);
  ModbusServer server(sim, 7);
  server.start_rtu_pty(19200);
  ModbusChamber chamber("chamber-rtu", mb::parse_endpoint(server.endpoint()), map, 0.5);
  ASSERT_TRUE(chamber.connect()) << server.endpoint();
  ASSERT_TRUE(chamber.command({.setpoint_c = 40.0, .ramp_c_per_min = 0.0}));
  sim.step_to(120.0);
  auto s = chamber.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_DOUBLE_EQ(s.value().setpoint_c, 40.0);
  EXPECT_NEAR(s.value().air_c, sim.air_c(), 0.05);
  EXPECT_GT(s.value().air_c, 25.0);
  server.inject_timeouts(1);
  auto t = chamber.read();
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().kind, ErrorKind::timeout);
  EXPECT_TRUE(chamber.read());
}

TEST(ModbusChamber, RtuRequestForAnotherUnitTimesOut) {
  ChamberSim sim(cm::generic_plc(2));
  ModbusServer server(sim, 2);
  server.start_rtu_pty();
  ModbusChamber chamber("chamber-rtu", mb::parse_endpoint(server.endpoint()), cm::generic_plc(3),
                        0.2);
  auto s = chamber.read();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::timeout);
}
