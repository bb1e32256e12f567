// The run's time left (daemon/time_left.hpp, issue 35): the one rule behind "step 4/5, 3 h 10 min
// left" on the terminal, in the log and in systemd's status line. The protocol runner is driven
// on a simulated clock (1 s ticks, the air following the setpoint at once), so the run's true end
// is known; the estimate must name it within what the steps themselves leave open.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "station/cli/progress_display.hpp"
#include "station/daemon/protocol_runner.hpp"
#include "station/daemon/time_left.hpp"

namespace station {
namespace {

// Step to 0 C, record, ramp to +40 C at 20 C/h (2 h), hold 10 min, stop: nominally 7800 s.
const char* kProtocol =
    "name = \"t\"\n"
    "[[step]]\ntype = \"set_temperature\"\nsetpoint_c = 0.0\ntolerance_c = 0.5\n"
    "[[step]]\ntype = \"record_start\"\n"
    "[[step]]\ntype = \"set_temperature\"\nsetpoint_c = 40.0\nramp_c_per_h = 20.0\n"
    "tolerance_c = 0.5\n"
    "[[step]]\ntype = \"hold\"\nduration_s = 600\n"
    "[[step]]\ntype = \"record_stop\"\n";
constexpr double kRampCPerH = 20.0;

/// The tolerance the steps leave: a ramp's setpoint is written when it moved 0.05 C (the runner's
/// write threshold), so its last commanded point lags by up to 0.05 C / rate; and every step
/// ends on a tick and the next begins on the next one (1 s per step).
double tolerance_s(const Protocol& p) {
  return 0.05 / kRampCPerH * 3600.0 + static_cast<double>(p.steps.size()) * 1.0;
}

StepPosition position(const ProtocolRunner& r, double t_s) {
  return {r.progress().step_index, t_s - r.progress().step_started_s, r.progress().start_temp_c,
          r.ramp_point_c(), r.setpoint_c()};
}

/// Runs the protocol from `progress` at `t0_s` to its end: the time left after each tick.
std::vector<std::pair<double, double>> run(const Protocol& p, RunProgress progress, double t0_s,
                                           double& end_s) {
  ProtocolRunner r(p, progress);
  Observation obs;
  obs.air_c = 25.0;
  std::vector<std::pair<double, double>> left;
  for (double t = t0_s; !r.done() && t < 20000; ++t) {
    obs.t_s = t;
    const auto a = r.tick(obs);
    if (a.chamber && a.chamber->setpoint_c) obs.air_c = *a.chamber->setpoint_c;
    const auto l = time_left_s(p, position(r, t));
    EXPECT_TRUE(l.has_value()) << "t = " << t;
    left.emplace_back(t, l.value_or(NAN));
    end_s = t;
  }
  return left;
}

TEST(TimeLeft, NamesTheRunsEndWithinWhatTheStepsLeaveOpen) {
  const Protocol p = parse_protocol(kProtocol, "t.toml");
  RunProgress start;
  start.start_temp_c = 25.0;
  double end_s = 0;
  const auto left = run(p, start, 0.0, end_s);
  EXPECT_NEAR(end_s, 7800.0, tolerance_s(p));  // the nominal duration, as the runner ends it
  for (const auto& [t, l] : left) ASSERT_NEAR(t + l, end_s, tolerance_s(p)) << "t = " << t;
  EXPECT_DOUBLE_EQ(left.back().second, 0.0);
}

TEST(TimeLeft, AResumedRunKnowsItsElapsedTimeFromTheStoredStepStart) {
  const Protocol p = parse_protocol(kProtocol, "t.toml");
  RunProgress resumed;  // killed an hour into the ramp, which started at t = 2
  resumed.step_index = 2;
  resumed.step_started_s = 2;
  resumed.recording = true;
  resumed.start_temp_c = 25.0;
  double end_s = 0;
  const auto left = run(p, resumed, 2 + 3600.0, end_s);
  // Half the ramp (1 h) and the hold (600 s) left, not the whole protocol.
  EXPECT_NEAR(left.front().second, 3600.0 + 600.0, tolerance_s(p));
  EXPECT_NEAR(left.front().first + left.front().second, end_s, tolerance_s(p));
}

TEST(TimeLeft, UnknownBeforeTheStartTemperatureOfARampFromIt) {
  const Protocol p = parse_protocol(
      "name = \"t\"\n[[step]]\ntype = \"set_temperature\"\nsetpoint_c = 40.0\nramp_c_per_h = "
      "20.0\n",
      "t.toml");
  EXPECT_FALSE(time_left_s(p, {}).has_value());
  StepPosition at;
  at.start_c = 30.0;  // 10 C at 20 C/h
  EXPECT_DOUBLE_EQ(*time_left_s(p, at), 1800.0);
}

TEST(TimeLeft, TextInHoursAndMinutesRoundedUp) {
  EXPECT_EQ(time_left_text(3 * 3600 + 9 * 60 + 1), "3 h 10 min left");
  EXPECT_EQ(time_left_text(25 * 60), "25 min left");
  EXPECT_EQ(time_left_text(59), "under 1 min left");
}

TickReport tick(double t_s, double left_s, bool hold) {
  TickReport r;
  r.t_s = t_s;
  r.run_id = 3;
  r.step_index = 3;
  r.steps = 5;
  r.step_label = "heat to +40 C at 20 C/h";
  r.time_left_s = left_s;
  r.safe_hold = hold;
  return r;
}

TEST(TimeLeft, ProgressShowsItAndASafeHoldExtendsTheRun) {
  EXPECT_EQ(ProgressDisplay::text(tick(9000, 3 * 3600 + 600, false), 0),
            "run 3  2.50 h  step 4/5, 3 h 10 min left: heat to +40 C at 20 C/h");
  std::vector<std::string> status;
  ProgressDisplay d(nullptr, false, 300.0, 600.0,
                    [&](const std::string& s) { status.push_back(s); });
  d.tick(tick(100, 3600, false));
  d.tick(tick(101, 3599, true));  // a hold of 20 min: the estimate stands still...
  d.tick(tick(1300, 2400, true));
  d.tick(tick(1301, 3598, false));  // ...and the run ends 20 min later than it said
  ASSERT_EQ(status.size(), 4u);
  for (int i = 0; i < 3; ++i) EXPECT_NE(status[i].find(", 1 h 0 min left"), std::string::npos) << i;
  EXPECT_NE(status[3].find(", 1 h 0 min left"), std::string::npos) << status[3];
}

}  // namespace
}  // namespace station
