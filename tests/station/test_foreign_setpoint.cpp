// Issue 34 point 3: another master writes the chamber's setpoint (simrig 'chamber setpoint 60',
// as the front panel or a second Modbus master would) during the recorded ramp, inside the
// limits, over real loopback sockets. The station reads back each tick what it commanded: the
// difference is one setpoint_foreign event (read and commanded), and by [chamber]
// on_foreign_setpoint the station's value is written again (restore, the default) or the run
// holds until the chamber reads the station's value again (hold).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/fault_commands.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/daemon/setpoint_watch.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"

namespace {

constexpr double kForeign_s = 4000, kOperator_s = 4100;  // during the recorded 20 C/h ramp
constexpr double kForeignC = 60.0;                       // inside the limits (-45..85 C)
constexpr double kStepC = 0.1;  // the coarsest setpoint register of these dialects: one decimal

std::vector<station::EventRow> of_kind(const std::vector<station::EventRow>& rows,
                                       const std::string& kind) {
  std::vector<station::EventRow> out;
  for (const auto& e : rows)
    if (e.kind == kind) out.push_back(e);
  return out;
}

nlohmann::json data_of(const station::EventRow& e) {
  return nlohmann::json::parse(e.data_json.value_or("null"));
}

class ForeignSetpointRun : public ::testing::TestWithParam<std::string> {};

TEST_P(ForeignSetpointRun, IsOneEventAndTheStationsSetpointIsRestored) {
  const std::string model = GetParam();
  const auto db = station::testing_support::fresh_db("foreign_sp_" + model);
  auto o = station::testing_support::short_cycle_run(db, 1);
  o.chamber_model = model;
  std::optional<double> ours_c;  // the station's setpoint when the other master writes
  o.on_world_tick = [&ours_c](double t_s, station::sim::SimWorld& w) {
    if (t_s != kForeign_s) return;
    ours_c = w.chamber().setpoint_c();
    const auto reply =
        station::sim::run_fault_command(w, fmt::format("chamber setpoint {}", kForeignC));
    EXPECT_EQ(reply.rfind("ok", 0), 0u) << reply;
  };
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  station::Store store(db);
  const auto run = r["run_id"].get<std::int64_t>();
  const auto rows = store.event_rows(run);
  const auto all = ::testing::PrintToString(store.events(run));
  ASSERT_TRUE(ours_c);

  // Seen at the first reading after the write, with what was read and what the station wants.
  const auto foreign = of_kind(rows, "setpoint_foreign");
  ASSERT_EQ(foreign.size(), 1u) << all;
  EXPECT_EQ(foreign[0].t_s, kForeign_s);
  EXPECT_EQ(foreign[0].source, "chamber");
  const auto d = data_of(foreign[0]);
  EXPECT_NEAR(d["read_c"].get<double>(), kForeignC, kStepC);
  EXPECT_NEAR(d["commanded_c"].get<double>(), *ours_c, kStepC);
  EXPECT_EQ(d["action"], "restore");
  // Written again at once: the next reading is the station's (or its ramp's next value).
  const auto back = of_kind(rows, "setpoint_foreign_end");
  ASSERT_EQ(back.size(), 1u) << all;
  EXPECT_EQ(back[0].t_s, kForeign_s + 1);
  EXPECT_TRUE(of_kind(rows, "safe_hold").empty()) << all;
  for (const auto& s : store.samples(run, "SIM-0001", false)) {
    if (s.t_s > kForeign_s && s.setpoint_c) EXPECT_LT(*s.setpoint_c, kForeignC - 1) << s.t_s;
  }
}

INSTANTIATE_TEST_SUITE_P(ChamberDialects, ForeignSetpointRun,
                         ::testing::Values("generic_plc", "watlow_f4t", "espec_p300", "watlow_f4"),
                         [](const auto& info) { return info.param; });

// on_foreign_setpoint = "hold": a safe hold that writes nothing over the other master's value;
// it ends when the chamber reads the station's setpoint again (the operator put it back at the
// panel), and the ramp resumes.
TEST(ForeignSetpoint, HoldModeHoldsUntilTheChamberReadsTheStationsSetpointAgain) {
  const auto db = station::testing_support::fresh_db("foreign_sp_hold");
  auto o = station::testing_support::short_cycle_run(db, 1);
  o.on_foreign_setpoint = "hold";
  std::optional<double> ours_c;
  o.on_world_tick = [&ours_c](double t_s, station::sim::SimWorld& w) {
    const auto cmd = [&](const std::string& c) {
      EXPECT_EQ(station::sim::run_fault_command(w, c).rfind("ok", 0), 0u) << c;
    };
    if (t_s == kForeign_s) {
      ours_c = w.chamber().setpoint_c();
      cmd(fmt::format("chamber setpoint {}", kForeignC));
    }
    if (t_s == kOperator_s && ours_c) cmd(fmt::format("chamber setpoint {:.6f}", *ours_c));
  };
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  station::Store store(db);
  const auto run = r["run_id"].get<std::int64_t>();
  const auto rows = store.event_rows(run);
  const auto all = ::testing::PrintToString(store.events(run));

  const auto foreign = of_kind(rows, "setpoint_foreign");
  ASSERT_EQ(foreign.size(), 1u) << all;
  EXPECT_EQ(foreign[0].t_s, kForeign_s);
  EXPECT_EQ(foreign[0].severity, "error");
  EXPECT_EQ(data_of(foreign[0])["action"], "hold");
  const auto holds = of_kind(rows, "safe_hold");
  ASSERT_EQ(holds.size(), 1u) << all;
  EXPECT_EQ(holds[0].t_s, kForeign_s);
  EXPECT_NE(holds[0].message.find("chamber setpoint written by another master"), std::string::npos)
      << holds[0].message;
  const auto back = of_kind(rows, "setpoint_foreign_end");
  ASSERT_EQ(back.size(), 1u) << all;
  EXPECT_EQ(back[0].t_s, kOperator_s);
  const auto cleared = of_kind(rows, "safe_hold_cleared");
  ASSERT_EQ(cleared.size(), 1u) << all;
  EXPECT_EQ(cleared[0].t_s, kOperator_s);
  EXPECT_EQ(of_kind(rows, "ramp_resume").size(), 1u) << all;
  // The hold wrote nothing over the other master's value: it read 60 C until the operator.
  for (const auto& s : store.samples(run, "SIM-0001", false)) {
    if (s.t_s < kForeign_s || s.t_s >= kOperator_s || !s.setpoint_c) continue;
    EXPECT_NEAR(*s.setpoint_c, kForeignC, kStepC) << s.t_s;
    // A sample carries the hold as it stood when it was read: from the tick after the event.
    if (s.t_s > kForeign_s) EXPECT_TRUE(s.flags & station::kSafeHold) << s.t_s;
  }
}

// The watch alone: a write whose reply was lost (a timeout: its outcome unknown) that reached the
// chamber reads back as the value tried, the station's own -- no event, no restore; a write the
// chamber refused (an exception reply) leaves the value tried forgotten, so that value read back
// is another master's.
TEST(ForeignSetpoint, AWriteWhoseReplyWasLostReadsBackAsTheStationsOwn) {
  const auto reading = [](double setpoint_c) {
    station::drivers::ChamberState c;
    c.setpoint_c = setpoint_c;
    return std::optional<station::drivers::ChamberState>(c);
  };
  station::SetpointWatch lost(station::ForeignSetpoint::hold);
  lost.commanded(23.0);
  EXPECT_TRUE(lost.observe(reading(23.0), kStepC).events.empty());
  lost.trying(40.0);
  lost.failed(true);  // timeout: it may have landed
  const auto news = lost.observe(reading(40.0), kStepC);
  EXPECT_TRUE(news.events.empty());
  EXPECT_FALSE(news.restore_c);
  EXPECT_FALSE(lost.foreign());
  EXPECT_TRUE(lost.observe(reading(40.0), kStepC).events.empty());  // and it stays the station's

  station::SetpointWatch refused;
  refused.commanded(23.0);
  refused.trying(40.0);
  refused.failed(false);  // refused: it never landed
  const auto other = refused.observe(reading(40.0), kStepC);
  ASSERT_EQ(other.events.size(), 1u);
  EXPECT_EQ(other.events[0].kind, station::EventKind::setpoint_foreign);
  EXPECT_EQ(other.restore_c, std::optional<double>(23.0));
}

}  // namespace
