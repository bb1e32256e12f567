// The safety layer's rules without a rig (judging readings against the limits, the safe-hold
// state) and once on the simulated rig: a setpoint written by someone else is caught.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "sim_devices/fault_commands.hpp"
#include "sim_devices/gpio_sim.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/daemon/safety.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

station::drivers::ChamberState chamber(double setpoint_c, double air_c) {
  station::drivers::ChamberState s;
  s.setpoint_c = setpoint_c;
  s.air_c = air_c;
  return s;
}

station::LimitsConfig limits() {
  station::LimitsConfig l;  // -45..85 C, air margin 5 C
  return l;
}

}  // namespace

TEST(Safety, ReadingsInsideTheLimitsAreNotJudged) {
  const station::Safety s(limits());
  EXPECT_TRUE(s.judge(chamber(85.0, 89.9)).empty());
  EXPECT_TRUE(s.judge(chamber(-45.0, -49.9)).empty());
  EXPECT_TRUE(s.judge(std::nullopt).empty());
  // A sensor break (NaN air) is the chamber's alarm, not a limits fault.
  EXPECT_TRUE(s.judge(chamber(20.0, NAN)).empty());
}

TEST(Safety, ASetpointReadBackOutsideTheLimitsIsAFault) {
  const station::Safety s(limits());
  const auto high = s.judge(chamber(150.0, 25.0));
  ASSERT_EQ(high.size(), 1u);
  EXPECT_NE(high[0].find("setpoint read back 150.00 C outside limits -45.0..85.0 C"),
            std::string::npos)
      << high[0];
  EXPECT_EQ(s.judge(chamber(-45.1, 25.0)).size(), 1u);
  EXPECT_EQ(s.judge(chamber(NAN, 25.0)).size(), 1u);
}

TEST(Safety, AirBeyondTheLimitsByTheMarginIsAFault) {
  auto l = limits();
  l.air_margin_c = 2.0;
  const station::Safety s(l);
  EXPECT_TRUE(s.judge(chamber(80.0, 87.0)).empty());
  const auto hot = s.judge(chamber(80.0, 87.1));
  ASSERT_EQ(hot.size(), 1u);
  EXPECT_NE(hot[0].find("air 87.10 C"), std::string::npos) << hot[0];
  EXPECT_EQ(s.judge(chamber(-40.0, -47.1)).size(), 1u);
  EXPECT_EQ(s.judge(chamber(150.0, 95.0)).size(), 2u);
}

TEST(Safety, ReadingsOutOfLimitsHoldUntilTheyAreBackInside) {
  station::Safety s(limits());
  EXPECT_FALSE(s.update(false, false, {}));
  const auto enter = s.update(false, false, s.judge(chamber(150.0, 25.0)));
  ASSERT_TRUE(enter);
  EXPECT_EQ(enter->rfind("enter: ", 0), 0u) << *enter;
  EXPECT_NE(enter->find("out of limits: chamber setpoint read back 150.00 C"), std::string::npos);
  EXPECT_TRUE(s.holding());
  EXPECT_TRUE(s.limits_fault());
  // The same fault on the next tick is no new message.
  EXPECT_FALSE(s.update(false, false, s.judge(chamber(150.0, 25.0))));
  // The hold is at the air temperature, inside the limits.
  EXPECT_DOUBLE_EQ(*s.hold_command(25.0).setpoint_c, 25.0);
  EXPECT_DOUBLE_EQ(*s.hold_command(96.0).setpoint_c, 85.0);
  const auto clear = s.update(false, false, s.judge(chamber(25.0, 25.0)));
  ASSERT_TRUE(clear);
  EXPECT_EQ(clear->rfind("clear: ", 0), 0u) << *clear;
  EXPECT_FALSE(s.holding());
  EXPECT_FALSE(s.limits_fault());
}

TEST(Safety, AFaultDuringAnInterlockHoldKeepsTheHoldAfterTheInterlockCloses) {
  station::Safety s(limits());
  ASSERT_TRUE(s.update(true, false, {}));
  const auto both = s.update(true, false, s.judge(chamber(150.0, 25.0)));
  ASSERT_TRUE(both);
  EXPECT_EQ(both->rfind("still holding: ", 0), 0u) << *both;
  s.update(false, false, s.judge(chamber(150.0, 25.0)));
  EXPECT_TRUE(s.holding());
}

// Issue 7 item 9: 150 C written to the chamber's setpoint register by another master during
// the recorded ramp (limit 85 C) -> one error event, safe hold, red lamp, setpoint back inside.
TEST(Safety, ASetpointWrittenBySomeoneElseIsCaughtOnTheSimulatedRig) {
  const auto db = station::testing_support::fresh_db("foreign_setpoint");
  station::SimRunOptions o;
  o.db_path = db;
  o.protocol = std::string(STATION_TEST_DATA_DIR) + "/short_cycle.toml";
  o.progress = false;
  o.fresh = true;
  o.gyros = 1;
  std::optional<bool> red_after, green_after, red_before;
  o.on_world_tick = [&](double t_s, station::sim::SimWorld& w) {
    if (t_s == 2999) red_before = w.gpio_chips()->pin_level("TOWER_R");
    if (t_s == 3000) {
      EXPECT_EQ(station::sim::run_fault_command(w, "chamber setpoint 150").rfind("ok", 0), 0u);
    }
    if (t_s == 3001) red_after = w.gpio_chips()->pin_level("TOWER_R");
    if (t_s == 3100) green_after = w.gpio_chips()->pin_level("TOWER_G");
  };
  const auto r = station::run_simulated(o);
  EXPECT_EQ(r["state"], "completed");
  station::Store store(db);
  const auto run = r["run_id"].get<std::int64_t>();
  int enters = 0;
  for (const auto& e : store.events(run)) {
    if (e.find("out of limits: chamber setpoint read back 150.00 C") != std::string::npos) {
      EXPECT_EQ(e.rfind("safe_hold: enter: ", 0), 0u) << e;
      ++enters;
    }
  }
  EXPECT_EQ(enters, 1) << ::testing::PrintToString(store.events(run));
  EXPECT_EQ(red_before, std::optional<bool>(false));
  EXPECT_EQ(red_after, std::optional<bool>(true));
  EXPECT_EQ(green_after, std::optional<bool>(true));
  bool held = false;
  for (const auto& s : store.samples(run, "SIM-0001", false)) {
    if (s.t_s == 3001) held = (s.flags & 16) != 0;
    if (s.t_s < 3002) continue;
    ASSERT_TRUE(s.setpoint_c) << s.t_s;
    EXPECT_LE(*s.setpoint_c, 85.0) << s.t_s;
  }
  EXPECT_TRUE(held);
}
