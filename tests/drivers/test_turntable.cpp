// ModbusTurntable against TurntableSim over TCP: trapezoidal moves, rate mode, stop, faults.
#include <gtest/gtest.h>

#include <cmath>

#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/generic_plc/modbus_turntable.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace mb = station::drivers::modbus;
using station::drivers::ErrorKind;
using station::drivers::ModbusTurntable;
using station::drivers::TurntableMode;

namespace {

// Default sim limits: v_max = 20 deg/s, a = 10 deg/s^2.
struct Rig {
  Rig() : sim(map), server(sim) {
    server.start_tcp();
    table = std::make_unique<ModbusTurntable>("table", mb::parse_endpoint(server.endpoint()), map);
  }
  mb::RegisterMap map = station::drivers::turntable_map::generic_plc();
  station::sim::TurntableSim sim;
  station::sim::ModbusServer server;
  std::unique_ptr<ModbusTurntable> table;
};

}  // namespace

// Trapezoid for a 90 deg move at v = 20 deg/s, a = 10 deg/s^2: accelerate for v/a = 2 s
// (covering v^2/2a = 20 deg), cruise 50 deg for 2.5 s, decelerate 2 s: total 6.5 s.
// At t = 1 s: x = a t^2 / 2 = 5 deg; at the midpoint t = 3.25 s: x = 45 deg by symmetry.
// Tolerance 1e-3 deg covers float32 resolution at 90 deg (~8e-6) and the discrete sqrt-profile
// deceleration (not reached before the midpoint).
TEST(ModbusTurntable, PositionMoveFollowsTrapezoidalProfile) {
  Rig rig;
  ASSERT_TRUE(rig.table->connect());
  ASSERT_TRUE(rig.table->command({.mode = TurntableMode::position, .position_deg = 90.0}));
  rig.sim.step_to(1.0);
  auto s1 = rig.table->read();
  ASSERT_TRUE(s1) << s1.error().message;
  EXPECT_NEAR(s1.value().angle_deg, 5.0, 1e-3);
  EXPECT_NEAR(s1.value().rate_dps, 10.0, 1e-3);
  EXPECT_EQ(s1.value().mode, TurntableMode::position);
  EXPECT_FALSE(s1.value().in_position);
  rig.sim.step_to(3.25);
  auto mid = rig.table->read();
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid.value().angle_deg, 45.0, 1e-3);
  EXPECT_NEAR(mid.value().rate_dps, 20.0, 1e-3);
  rig.sim.step_to(7.0);
  auto end = rig.table->read();
  ASSERT_TRUE(end);
  EXPECT_NEAR(end.value().angle_deg, 90.0, 0.01);
  EXPECT_TRUE(end.value().in_position);
}

TEST(ModbusTurntable, ShortestPathAcrossZeroAndWrappedDemand) {
  Rig rig;
  ASSERT_TRUE(rig.table->command({.mode = TurntableMode::position, .position_deg = -10.0}));
  rig.sim.step_to(1.0);
  auto s = rig.table->read();
  ASSERT_TRUE(s);
  EXPECT_NEAR(s.value().angle_deg, 355.0, 1e-3);  // moved -5 deg, shown in [0, 360)
  rig.sim.step_to(5.0);
  auto end = rig.table->read();
  ASSERT_TRUE(end);
  EXPECT_NEAR(end.value().angle_deg, 350.0, 0.01);
  EXPECT_TRUE(end.value().in_position);
}

TEST(ModbusTurntable, RateModeReachesRateAfterAccelerationThenStops) {
  Rig rig;
  ASSERT_TRUE(rig.table->command({.mode = TurntableMode::rate, .rate_dps = -15.0}));
  rig.sim.step_to(1.0);
  auto s = rig.table->read();
  ASSERT_TRUE(s);
  EXPECT_NEAR(s.value().rate_dps, -10.0, 1e-4);
  EXPECT_FALSE(s.value().at_rate);
  rig.sim.step_to(2.0);
  auto r = rig.table->read();
  ASSERT_TRUE(r);
  EXPECT_NEAR(r.value().rate_dps, -15.0, 1e-4);
  EXPECT_TRUE(r.value().at_rate);
  ASSERT_TRUE(rig.table->stop());
  rig.sim.step_to(3.0);  // 15 deg/s at 10 deg/s^2 takes 1.5 s to stop
  auto slowing = rig.table->read();
  ASSERT_TRUE(slowing);
  EXPECT_NEAR(slowing.value().rate_dps, -5.0, 1e-4);
  rig.sim.step_to(4.0);
  auto stopped = rig.table->read();
  ASSERT_TRUE(stopped);
  EXPECT_EQ(stopped.value().rate_dps, 0.0);
  EXPECT_EQ(stopped.value().mode, TurntableMode::off);
}

TEST(ModbusTurntable, InterlockDisablesDriveAndRefusesEnable) {
  Rig rig;
  rig.sim.set_interlock_open(true);
  ASSERT_TRUE(rig.table->command({.mode = TurntableMode::rate, .rate_dps = 5.0}));
  rig.sim.step_to(1.0);
  auto s = rig.table->read();
  ASSERT_TRUE(s);
  EXPECT_TRUE(s.value().interlock_open);
  EXPECT_EQ(s.value().mode, TurntableMode::off);
  EXPECT_EQ(s.value().rate_dps, 0.0);
  rig.sim.set_interlock_open(false);
  rig.sim.set_fault(true);
  auto f = rig.table->read();
  ASSERT_TRUE(f);
  EXPECT_TRUE(f.value().fault);
  EXPECT_FALSE(f.value().interlock_open);
}

TEST(ModbusTurntable, LockHoldsTheAxis) {
  Rig rig;
  ASSERT_TRUE(rig.table->command({.mode = TurntableMode::rate, .rate_dps = 5.0, .lock = true}));
  rig.sim.step_to(1.0);
  EXPECT_EQ(rig.sim.rate_dps(), 0.0);
  ASSERT_TRUE(rig.table->command({.mode = TurntableMode::rate, .rate_dps = 5.0, .lock = false}));
  rig.sim.step_to(2.0);
  EXPECT_NEAR(rig.sim.rate_dps(), 5.0, 1e-9);
}

TEST(ModbusTurntable, OutOfRangeDemandIsRangeAndNothingIsSent) {
  Rig rig;
  auto r = rig.table->command({.mode = TurntableMode::rate, .rate_dps = 900.0});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::range);
  auto n = rig.table->command({.mode = TurntableMode::position, .position_deg = NAN});
  ASSERT_FALSE(n);
  EXPECT_EQ(n.error().kind, ErrorKind::range);
  EXPECT_EQ(rig.server.requests(), 0u);
}

TEST(ModbusTurntable, OneReadIsOneBlockTransaction) {
  Rig rig;
  ASSERT_TRUE(rig.table->connect());
  const auto before = rig.server.requests();
  auto s = rig.table->read();
  ASSERT_TRUE(s) << s.error().message;
  // Input registers 100..105 (mode, angle, rate, status) in one read instead of four, and the
  // lock read back from its holding register.
  EXPECT_EQ(rig.server.requests() - before, 2u);
  EXPECT_EQ(s.value().mode, TurntableMode::off);
}

TEST(ModbusTurntable, InjectedFaultsGiveTypedErrorsThenRecover) {
  Rig rig;
  rig.server.inject_timeouts(1);
  EXPECT_EQ(rig.table->read().error().kind, ErrorKind::timeout);
  rig.server.inject_exception(MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE);
  EXPECT_EQ(rig.table->stop().error().kind, ErrorKind::exception);
  rig.server.inject_drop();
  EXPECT_EQ(rig.table->read().error().kind, ErrorKind::disconnected);
  EXPECT_TRUE(rig.table->read());
}

// The lock register is read back every N reads and after a write (drivers/modbus/readback.hpp);
// mode, angle, rate and status (one block) on every read.
TEST(ModbusTurntable, LockIsReadBackEveryNReadsAndAfterAWrite) {
  Rig rig;
  rig.table->set_readback_every(3);
  ASSERT_TRUE(rig.table->connect());
  const auto requests_of_read = [&] {
    const std::uint64_t before = rig.server.requests();
    EXPECT_TRUE(rig.table->read());
    return rig.server.requests() - before;
  };
  std::vector<std::uint64_t> seen;
  for (int i = 0; i < 7; ++i) seen.push_back(requests_of_read());
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{2, 1, 1, 2, 1, 1, 2}));
  ASSERT_TRUE(rig.table->command({.lock = true}));
  const std::uint64_t before = rig.server.requests();
  auto s = rig.table->read();
  ASSERT_TRUE(s);
  EXPECT_EQ(rig.server.requests() - before, 2u);
  EXPECT_TRUE(s.value().locked);
}
