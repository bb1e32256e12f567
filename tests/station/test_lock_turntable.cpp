// The lock_turntable step with ModbusTurntable and the simulated table over real Modbus TCP:
// move, in position at the commanded angle, then lock; done only on a reading after the lock.
#include <gtest/gtest.h>

#include <cmath>

#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/generic_plc/modbus_turntable.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "sim_devices/turntable_sim.hpp"
#include "station/daemon/protocol_runner.hpp"

namespace mb = station::drivers::modbus;
using station::drivers::TurntableMode;

// Issue 7 item 10: a table parked and locked at 90 deg, a protocol locking it at 0 deg.
TEST(LockTurntable, ATableLockedAt90IsMovedTo0ThenLocked) {
  const auto map = station::drivers::turntable_map::generic_plc();
  station::sim::TurntableSim sim(map);
  station::sim::ModbusServer server(sim);
  server.start_tcp();
  station::drivers::ModbusTurntable table("table", mb::parse_endpoint(server.endpoint()), map);
  ASSERT_TRUE(table.connect());
  ASSERT_TRUE(table.command({.mode = TurntableMode::position, .position_deg = 90.0}));
  sim.step_to(10.0);
  ASSERT_TRUE(table.command({.mode = TurntableMode::position, .lock = true}));
  ASSERT_TRUE(table.read().value().locked);

  station::Protocol p;
  p.name = "lock";
  station::Step s;
  s.kind = station::StepKind::lock_turntable;
  s.position_deg = 0.0;
  s.label = "lock at 0";
  p.steps.push_back(s);
  station::ProtocolRunner runner(p, station::RunProgress{});
  // Each tick as the sequencer does it: read, runner, command; the sim advances 1 s per tick.
  double done_at_s = -1;
  for (int t = 0; t < 60 && done_at_s < 0; ++t) {
    sim.step_to(10.0 + t);
    const auto st = table.read();
    ASSERT_TRUE(st) << st.error().message;
    station::Observation obs;
    obs.t_s = t;
    obs.has_turntable = true;
    obs.table_in_position = st.value().in_position;
    obs.table_angle_deg = st.value().angle_deg;
    obs.table_locked = st.value().locked;
    const auto a = runner.tick(obs);
    if (a.table) {
      ASSERT_TRUE(table.command(*a.table));
    }
    if (runner.done()) done_at_s = t;
  }
  // 90 deg at 20 deg/s max, 10 deg/s^2: 6.5 s of motion, so not before t = 7 s (a stale
  // reading at 90 deg in position and locked would end the step at t = 0).
  ASSERT_GE(done_at_s, 7.0);
  const auto end = table.read();
  ASSERT_TRUE(end);
  EXPECT_NEAR(std::remainder(end.value().angle_deg, 360.0), 0.0, 0.01);
  EXPECT_TRUE(end.value().in_position);
  EXPECT_TRUE(end.value().locked);
}
