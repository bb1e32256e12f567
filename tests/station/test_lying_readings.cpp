// Issue 34 point 2: a chamber whose air reading lies for 10 s (a P300's 99999.9, a word pair or
// register saturated at its end, the F4's 0x8000) during the recorded ramp, then tells the truth
// again, over real loopback sockets on each dialect. A reading outside what the device can
// report is a fault, never a value: one implausible_reading event and its end, the samples kept
// with air empty, a safe hold once it lasted as long as an unreadable input may (5 ticks), and
// the ramp resumes from a trusted reading -- no clamp events, no setpoint driven to a limit.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sim_devices/fault_commands.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/daemon/plausibility.hpp"
#include "station/daemon/safety.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"

namespace {

constexpr double kLie_s = 4000, kTruth_s = 4010;  // during the recorded 20 C/h ramp
constexpr double kRampCPerH = 20.0;               // tests/data/short_cycle.toml
constexpr double kHeatCPerMin = 3.0;              // the simulated chamber's fastest change

struct Lie {
  const char* model;
  const char* air;  ///< what the air reading shows (simrig 'chamber air C')
};

class LyingAirRun : public ::testing::TestWithParam<Lie> {};

std::vector<station::EventRow> of_kind(const std::vector<station::EventRow>& rows,
                                       const std::string& kind) {
  std::vector<station::EventRow> out;
  for (const auto& e : rows)
    if (e.kind == kind) out.push_back(e);
  return out;
}

TEST_P(LyingAirRun, IsAFaultNeverAValueAndTheRampResumesFromATrustedReading) {
  const Lie lie = GetParam();
  const auto db = station::testing_support::fresh_db(std::string("lying_air_") + lie.model);
  auto o = station::testing_support::short_cycle_run(db, 1);
  o.chamber_model = lie.model;
  o.on_world_tick = [&lie](double t_s, station::sim::SimWorld& w) {
    const auto cmd = [&](const std::string& c) {
      EXPECT_EQ(station::sim::run_fault_command(w, c).rfind("ok", 0), 0u) << c;
    };
    if (t_s == kLie_s) cmd(std::string("chamber air ") + lie.air);
    if (t_s == kTruth_s) cmd("chamber air off");
  };
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  station::Store store(db);
  const auto run = r["run_id"].get<std::int64_t>();
  const auto rows = store.event_rows(run);
  const auto all = ::testing::PrintToString(store.events(run));

  // One episode: its start at the first lying reading, its end at the first true one.
  const auto found = of_kind(rows, "implausible_reading");
  ASSERT_EQ(found.size(), 1u) << all;
  EXPECT_EQ(found[0].t_s, kLie_s);
  EXPECT_EQ(found[0].source, "chamber");
  const auto data = nlohmann::json::parse(found[0].data_json.value_or("null"));
  EXPECT_EQ(data["device"], "chamber");
  EXPECT_EQ(data["quantity"], "air_c");
  const auto ends = of_kind(rows, "implausible_reading_end");
  ASSERT_EQ(ends.size(), 1u) << all;
  EXPECT_EQ(ends[0].t_s, kTruth_s);

  // A safe hold once the lie lasted kBlindTicks, cleared when the air reads plausibly again.
  const auto holds = of_kind(rows, "safe_hold");
  ASSERT_EQ(holds.size(), 1u) << all;
  EXPECT_EQ(holds[0].t_s, kLie_s + station::Safety::kBlindTicks - 1);
  EXPECT_NE(holds[0].message.find("chamber air reading implausible"), std::string::npos)
      << holds[0].message;
  const auto cleared = of_kind(rows, "safe_hold_cleared");
  ASSERT_EQ(cleared.size(), 1u) << all;
  EXPECT_EQ(cleared[0].t_s, kTruth_s);
  EXPECT_TRUE(of_kind(rows, "outage_start").empty()) << all;  // the chamber answered throughout
  // No setpoint ever driven to a limit (a protocol note at t = 0 is the run's start, not this).
  for (const auto& e : of_kind(rows, "clamp")) EXPECT_EQ(e.t_s, 0.0) << e.message;

  // Every tick kept; the lying ones with air empty.
  const auto samples = station::Store(db).samples(run, "SIM-0001", false);
  std::optional<double> last_good_c, air_at_clear_c;
  int lying = 0;
  for (const auto& s : samples) {
    if (s.t_s < kLie_s && s.air_c) last_good_c = s.air_c;
    if (s.t_s == kTruth_s) air_at_clear_c = s.air_c;
    if (s.t_s < kLie_s || s.t_s >= kTruth_s) continue;
    EXPECT_FALSE(s.air_c) << s.t_s << ": air " << *s.air_c << " stored as a value";
    ++lying;
  }
  EXPECT_EQ(lying, static_cast<int>(kTruth_s - kLie_s));
  ASSERT_TRUE(last_good_c);
  ASSERT_TRUE(air_at_clear_c);

  // The ramp resumes from the trusted reading at the clear, within what the chamber can have
  // moved since the last good one; every setpoint after it on the ramp from there.
  const auto resumes = of_kind(rows, "ramp_resume");
  ASSERT_EQ(resumes.size(), 1u) << all;
  const double from_c =
      nlohmann::json::parse(resumes[0].data_json.value_or("{}"))["from_c"].get<double>();
  EXPECT_NEAR(from_c, *air_at_clear_c, 1e-9);
  EXPECT_NEAR(from_c, *last_good_c, kHeatCPerMin * (kTruth_s - kLie_s + 1) / 60.0);
  constexpr double kStepC = 0.1;  // one setpoint register step (a P300's one decimal)
  for (const auto& s : samples) {
    if (s.t_s <= kTruth_s + 1 || s.t_s > kTruth_s + 600 || !s.setpoint_c) continue;
    const double ramp_c = from_c + kRampCPerH * (s.t_s - kTruth_s) / 3600.0;
    EXPECT_GE(*s.setpoint_c, from_c - kStepC) << s.t_s;
    EXPECT_LE(*s.setpoint_c, ramp_c + kStepC) << s.t_s;
  }
}

INSTANTIATE_TEST_SUITE_P(ChamberDialects, LyingAirRun,
                         ::testing::Values(Lie{"espec_p300", "99999.9"},
                                           Lie{"generic_plc", "1e308"}, Lie{"watlow_f4", "-1e308"},
                                           Lie{"watlow_f4t", "1e30"}),
                         [](const auto& info) { return std::string(info.param.model); });

// Issue 34 review point 10: air beyond the configured limits that the chamber's sensor can read
// (150 C against max_setpoint_c 85) is a real reading out of limits -- the immediate safe hold --
// never an "implausible" one waiting kBlindTicks with the gyros powered.
TEST(OutOfLimitsAir, IsARealReadingHeldAtOnceNotAnImplausibleOne) {
  const auto db = station::testing_support::fresh_db("out_of_limits_air");
  auto o = station::testing_support::short_cycle_run(db, 1);
  o.on_world_tick = [](double t_s, station::sim::SimWorld& w) {
    if (t_s == kLie_s) EXPECT_EQ(station::sim::run_fault_command(w, "chamber air 150"), "ok");
    if (t_s == kTruth_s) EXPECT_EQ(station::sim::run_fault_command(w, "chamber air off"), "ok");
  };
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  station::Store store(db);
  const auto run = r["run_id"].get<std::int64_t>();
  const auto rows = store.event_rows(run);
  const auto all = ::testing::PrintToString(store.events(run));
  EXPECT_TRUE(of_kind(rows, "implausible_reading").empty()) << all;
  const auto holds = of_kind(rows, "safe_hold");
  ASSERT_EQ(holds.size(), 1u) << all;
  EXPECT_EQ(holds[0].t_s, kLie_s) << all;
  EXPECT_NE(holds[0].message.find("beyond limits"), std::string::npos) << holds[0].message;
}

// The chamber's setpoint read-back and the table's angle pass the same rule as the air: 1e308 or
// a float32 subnormal is taken out (NaN: stored NULL, no position, not the setpoint watch's).
TEST(ScreenReading, SetpointReadBackAndTableAngleAreScreenedByTheSameRule) {
  for (const double lie : {1e308, -4.6e-41}) {
    station::RigReading in;
    in.chamber = station::drivers::ChamberState{};
    in.chamber->air_c = 150.0;  // out of limits, yet a reading
    in.chamber->setpoint_c = lie;
    in.table = station::drivers::TurntableState{};
    in.table->angle_deg = lie;
    in.has_table = true;
    auto ranges = station::plausible_ranges(station::Rig{});  // a chamber's default range
    ranges.angle_deg = {-360.0, 360.0};  // a table's default (Turntable::angle_range_deg)
    const auto found = station::screen_reading(in, ranges);
    std::vector<std::string> what;
    for (const auto& f : found) what.push_back(f.device + " " + f.quantity);
    EXPECT_EQ(what, (std::vector<std::string>{"chamber setpoint_c", "turntable angle_deg"})) << lie;
    EXPECT_TRUE(std::isnan(in.chamber->setpoint_c)) << lie;
    ASSERT_TRUE(in.table) << lie;  // the rest of the table's reading stands
    EXPECT_TRUE(std::isnan(in.table->angle_deg)) << lie;
    EXPECT_EQ(in.chamber->air_c, 150.0);
  }
}

}  // namespace
