// Issue 34 point 4: every alarm a chamber dialect reports is an event when it comes on and when
// it goes off during a run, over real loopback sockets; the ones that make the air untrustworthy
// hold. The generic map's high-limit trip and door; an ESPEC P300's alarm (ALARM? codes, the
// driver's `other`) with the simulator's broken sensor, whose air reading 999.9 C no chamber
// gives: a chamber_alarm, an implausible air (samples keep air empty) and a safe hold.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim_devices/fault_commands.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/daemon/safety.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"

namespace {

constexpr double kOn_s = 4000, kOff_s = 4030;  // during the recorded 20 C/h ramp

std::vector<station::EventRow> of_kind(const std::vector<station::EventRow>& rows,
                                       const std::string& kind) {
  std::vector<station::EventRow> out;
  for (const auto& e : rows)
    if (e.kind == kind) out.push_back(e);
  return out;
}

struct AlarmCase {
  const char* model;
  const char* on;     ///< simrig command
  const char* off;    ///< simrig command
  const char* alarm;  ///< the event's `alarm`
};

class ChamberAlarmRun : public ::testing::TestWithParam<AlarmCase> {};

TEST_P(ChamberAlarmRun, IsAnEventEachWayAndAHold) {
  const AlarmCase c = GetParam();
  const auto db = station::testing_support::fresh_db(std::string("alarm_") + c.model + c.alarm);
  auto o = station::testing_support::short_cycle_run(db, 1);
  o.chamber_model = c.model;
  o.on_world_tick = [&c](double t_s, station::sim::SimWorld& w) {
    const auto cmd = [&](const char* text) {
      EXPECT_EQ(station::sim::run_fault_command(w, text).rfind("ok", 0), 0u) << text;
    };
    if (t_s == kOn_s) cmd(c.on);
    if (t_s == kOff_s) cmd(c.off);
  };
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  station::Store store(db);
  const auto run = r["run_id"].get<std::int64_t>();
  const auto rows = store.event_rows(run);
  const auto all = ::testing::PrintToString(store.events(run));

  std::vector<station::EventRow> on, off;
  for (const auto& e : of_kind(rows, "chamber_alarm"))
    if (nlohmann::json::parse(*e.data_json)["alarm"] == c.alarm) on.push_back(e);
  for (const auto& e : of_kind(rows, "chamber_alarm_cleared"))
    if (nlohmann::json::parse(*e.data_json)["alarm"] == c.alarm) off.push_back(e);
  ASSERT_EQ(on.size(), 1u) << all;
  EXPECT_EQ(on[0].t_s, kOn_s);
  EXPECT_EQ(on[0].source, "safety");
  ASSERT_EQ(off.size(), 1u) << all;
  EXPECT_EQ(off[0].t_s, kOff_s);
  // It holds, and the hold ends with it.
  const auto holds = of_kind(rows, "safe_hold");
  ASSERT_EQ(holds.size(), 1u) << all;
  EXPECT_GE(holds[0].t_s, kOn_s);
  EXPECT_LE(holds[0].t_s, kOn_s + station::Safety::kBlindTicks - 1);
  const auto cleared = of_kind(rows, "safe_hold_cleared");
  ASSERT_EQ(cleared.size(), 1u) << all;
  EXPECT_EQ(cleared[0].t_s, kOff_s);
  // Nothing stored as air that the chamber could not have had.
  for (const auto& s : store.samples(run, "SIM-0001", false))
    if (s.air_c) EXPECT_LT(*s.air_c, 200.0) << s.t_s;
}

INSTANTIATE_TEST_SUITE_P(
    Alarms, ChamberAlarmRun,
    ::testing::Values(AlarmCase{"generic_plc", "chamber alarm high-limit on",
                                "chamber alarm high-limit off", "high_limit_trip"},
                      AlarmCase{"generic_plc", "door open", "door close", "door_open"},
                      AlarmCase{"espec_p300", "chamber alarm sensor on", "chamber alarm sensor off",
                                "other"}),
    [](const auto& info) { return std::string(info.param.model) + "_" + info.param.alarm; });

}  // namespace
