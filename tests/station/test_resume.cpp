// Resume decisions: only the same rig continues a run, with its stored protocol; --new and
// mismatches mark the old run aborted.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>

#include "station/daemon/resume.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::testing_support::fresh_db;

station::StationConfig config_with(const std::string& serial2) {
  return station::parse_station_config(
      "[station]\nlatitude_deg = 40\n[chamber]\nendpoint = \"tcp://127.0.0.1:502\"\n[can]\n"
      "transport = \"unix:/tmp/x.sock\"\n[[slot]]\nnode = 1\nserial = \"A\"\n[[slot]]\nnode = 2\n"
      "serial = \"" +
          serial2 + "\"\n",
      "rig.toml");
}

std::int64_t start_run(station::Store& s) {
  const std::string protocol = "name = \"p\"\n[[step]]\ntype = \"hold\"\nduration_s = 60\n";
  return s.create_run({"p", protocol, "", "0", "rig", "", std::nullopt, 0.0, {}},
                      {{0, 1, "A", "up", 1.5, 9.6}, {1, 2, "B", "up", 1.5, 9.6}});
}

}  // namespace

TEST(Resume, SameSlotsContinueWithTheStoredProtocol) {
  station::Store s(fresh_db("resume-same"));
  const auto id = start_run(s);
  const auto d = station::decide_resume(s, config_with("B"), false, false);
  ASSERT_TRUE(d.run.has_value());
  EXPECT_EQ(d.run->id, id);
  ASSERT_TRUE(d.protocol.has_value());
  EXPECT_EQ(d.protocol->name, "p");
}

TEST(Resume, OtherSlotsAreRefusedNamingTheDifference) {
  station::Store s(fresh_db("resume-other"));
  start_run(s);
  try {
    station::decide_resume(s, config_with("C"), false, false);
    FAIL() << "expected InputError";
  } catch (const station::InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("started with slots A@1 B@2 but the configuration has A@1 C@2"),
        std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--new"), std::string::npos);
  }
  EXPECT_TRUE(s.find_unfinished_run().has_value());  // refused, not touched
}

TEST(Resume, NewOrMismatchMarksTheOldRunAborted) {
  station::Store s(fresh_db("resume-new"));
  const auto first = start_run(s);
  EXPECT_FALSE(station::decide_resume(s, config_with("B"), true, false).run.has_value());
  EXPECT_EQ(s.find_run(first)->state, station::RunState::aborted);
  const auto second = start_run(s);
  EXPECT_FALSE(station::decide_resume(s, config_with("C"), false, true).run.has_value());
  EXPECT_EQ(s.find_run(second)->state, station::RunState::aborted);
  EXPECT_EQ(s.events(second).back().rfind("aborted: run", 0), 0u);
}

namespace {

std::string rig_text(double pulse_weight, double latitude, const std::string& axis = "up") {
  return fmt::format(
      "[station]\nlatitude_deg = {}\n[chamber]\nendpoint = \"tcp://127.0.0.1:502\"\n[can]\n"
      "transport = \"unix:/tmp/x.sock\"\n[[slot]]\nnode = 1\nserial = \"A\"\n[[slot]]\nnode = 2\n"
      "serial = \"B\"\npulse_weight_arcsec = {}\naxis = \"{}\"\n",
      latitude, pulse_weight, axis);
}

std::int64_t start_resolved_run(station::Store& s, const station::StationConfig& c) {
  const std::string protocol = "name = \"p\"\n[[step]]\ntype = \"hold\"\nduration_s = 60\n";
  station::RunInfo info{
      "p", protocol, c.text, "0", "rig", "", std::nullopt, 0.0, station::resolved_meaning_json(c)};
  return s.create_run(info, {{0, 1, "A", "up", 1.5, 9.6}, {1, 2, "B", "up", 1.5, 9.6}});
}

std::string refusal(station::Store& s, const station::StationConfig& c) {
  try {
    station::decide_resume(s, c, false, false);
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(Resume, AChangedPulseWeightIsRefusedWithAOneLineDiff) {
  // Issue 7.3: pulse weight 1.5 -> 3.0 on resume doubled every later rate, silently.
  station::Store s(fresh_db("resume-pw"));
  start_resolved_run(s, station::parse_station_config(rig_text(1.5, 40), "rig.toml"));
  const auto why = refusal(s, station::parse_station_config(rig_text(3.0, 40), "rig.toml"));
  EXPECT_NE(why.find("slots/1/pulse_weight_arcsec 1.5 -> 3.0"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << "not one line: " << why;
  EXPECT_TRUE(s.find_unfinished_run().has_value());
}

TEST(Resume, LatitudeAndAxisChangesAreRefusedToo) {
  station::Store s(fresh_db("resume-lat"));
  start_resolved_run(s, station::parse_station_config(rig_text(1.5, 40), "rig.toml"));
  const auto lat = refusal(s, station::parse_station_config(rig_text(1.5, 41), "rig.toml"));
  EXPECT_NE(lat.find("latitude_deg 40"), std::string::npos) << lat;
  EXPECT_NE(lat.find("slots/0/earth_rate_dph"), std::string::npos) << lat;
  const auto axis =
      refusal(s, station::parse_station_config(rig_text(1.5, 40, "north"), "rig.toml"));
  EXPECT_NE(axis.find("slots/1/axis \"up\" -> \"north\""), std::string::npos) << axis;
}

TEST(Resume, TheSameMeaningContinuesEvenWithOtherEndpoints) {
  station::Store s(fresh_db("resume-endpoint"));
  const auto id =
      start_resolved_run(s, station::parse_station_config(rig_text(1.5, 40), "rig.toml"));
  std::string moved = rig_text(1.5, 40);
  moved.replace(moved.find("127.0.0.1:502"), 13, "10.0.0.7:5020");
  const auto d =
      station::decide_resume(s, station::parse_station_config(moved, "rig.toml"), false, false);
  ASSERT_TRUE(d.run.has_value());
  EXPECT_EQ(d.run->id, id);
}
