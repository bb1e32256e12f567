// The one start rule (station/daemon/run_start.hpp): only the same rig (or the same simulation)
// continues a run, with its stored protocol; --new marks the old run aborted; a mismatch is
// refused naming the difference; a broken rig refuses a new run but not a resume.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>

#include "station/daemon/resume.hpp"
#include "station/daemon/run_start.hpp"
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

/// A request to continue or start, as `run --config` makes it (protocol "p", as stored).
station::StartRequest ask(bool fresh = false, std::optional<std::int64_t> seed = std::nullopt,
                          std::vector<std::string> problems = {}) {
  return {station::parse_protocol("name = \"p\"\n[[step]]\ntype = \"hold\"\nduration_s = 60\n",
                                  "p.toml"),
          fresh, seed, std::move(problems)};
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
  const auto d = station::start_run(s, config_with("B"), ask());
  ASSERT_TRUE(d.resume.has_value());
  EXPECT_EQ(d.resume->id, id);
  EXPECT_EQ(d.protocol.name, "p");
  EXPECT_TRUE(d.warnings.empty());
  EXPECT_FALSE(d.replay_until_t_s.has_value()) << "a rig continues at the elapsed time";
}

TEST(Resume, ItKeepsItsOwnSerialsWhateverTheConfigurationNowSays) {
  // Issue 35: the gyros belong to the run; the configuration's serials are defaults of new runs.
  station::Store s(fresh_db("resume-own-serials"));
  const auto id = start_run(s);
  const auto d = station::start_run(s, config_with("C"), ask());
  ASSERT_TRUE(d.resume.has_value());
  EXPECT_EQ(d.resume->id, id);
  EXPECT_EQ(d.config.slots[1].serial, "B");
}

TEST(Resume, OtherSerialsGivenAreRefusedNamingTheDifference) {
  station::Store s(fresh_db("resume-other"));
  start_run(s);
  auto other = ask();
  other.gyros = {{2, "C", ""}};
  try {
    station::start_run(s, config_with("B"), other);
    FAIL() << "expected InputError";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("was started with other gyros: slot 2 serial 'B' -> 'C'"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--new"), std::string::npos);
  }
  EXPECT_TRUE(s.find_unfinished_run().has_value());  // refused, not touched
}

TEST(Resume, NewMarksTheOldRunAbortedEvenWhenItWouldNotMatch) {
  station::Store s(fresh_db("resume-new"));
  const auto first = start_run(s);
  EXPECT_FALSE(station::start_run(s, config_with("B"), ask(true)).resume.has_value());
  EXPECT_EQ(s.find_run(first)->state, station::RunState::aborted);
  EXPECT_EQ(s.events(first).back().rfind("aborted: superseded by a new run (--new)", 0), 0u)
      << s.events(first).back();
  const auto second = start_run(s);
  EXPECT_FALSE(station::start_run(s, config_with("C"), ask(true)).resume.has_value());
  EXPECT_EQ(s.find_run(second)->state, station::RunState::aborted);
}

TEST(Resume, AnotherSourceIsRefusedNamingBoth) {
  // A rig's run is never continued by a simulation, nor a simulation by another seed.
  station::Store s(fresh_db("resume-source"));
  start_run(s);  // a rig's run (no seed)
  try {
    station::start_run(s, config_with("B"), ask(false, 7));
    FAIL() << "a simulation continued a rig's run";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("was made by a rig, this start is a simulation of seed 7"),
              std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(s.find_unfinished_run().has_value());  // refused, not touched
}

TEST(Resume, ASimulationContinuesOnlyBySameSeedAndReplaysFromZero) {
  station::Store s(fresh_db("resume-sim"));
  const std::string protocol = "name = \"p\"\n[[step]]\ntype = \"hold\"\nduration_s = 60\n";
  const auto id = s.create_run({"p", protocol, "", "0", "rig", "", 5, 0.0, {}},
                               {{0, 1, "A", "up", 1.5, 9.6}, {1, 2, "B", "up", 1.5, 9.6}});
  s.append_tick(id, 0, {}, {});
  s.append_tick(id, 1, {}, {});
  s.flush();
  EXPECT_THROW(station::start_run(s, config_with("B"), ask(false, 6)), station::InputError);
  const auto d = station::start_run(s, config_with("B"), ask(false, 5));
  ASSERT_TRUE(d.resume.has_value());
  ASSERT_TRUE(d.replay_until_t_s.has_value());
  EXPECT_EQ(*d.replay_until_t_s, 1.0);  // recompute t = 0 and 1, store from t = 2 on
}

TEST(Resume, ItContinuesWithItsOwnProtocolAndSaysSo) {
  station::Store s(fresh_db("resume-protocol"));
  start_run(s);
  auto other = ask();
  other.protocol = station::parse_protocol(
      "name = \"q\"\n[[step]]\ntype = \"hold\"\nduration_s = 90\n", "q.toml");
  const auto d = station::start_run(s, config_with("B"), other);
  ASSERT_TRUE(d.resume.has_value());
  EXPECT_EQ(d.protocol.name, "p");
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("continues with the protocol stored with it ('p'), not 'q'"),
            std::string::npos)
      << d.warnings[0];
}

TEST(Resume, ABrokenRigRefusesANewRunButNotAResume) {
  station::Store s(fresh_db("resume-devices"));
  const std::vector<std::string> problems{"rig.toml: chamber tcp://x unreachable: timeout"};
  // No unfinished run: the start is refused with the check's lines, nothing is created.
  EXPECT_THROW(station::start_run(s, config_with("B"), ask(false, std::nullopt, problems)),
               station::InputError);
  EXPECT_FALSE(s.find_unfinished_run().has_value());
  const auto id = start_run(s);
  const auto d = station::start_run(s, config_with("B"), ask(false, std::nullopt, problems));
  ASSERT_TRUE(d.resume.has_value());
  EXPECT_EQ(d.resume->id, id);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_EQ(d.warnings[0], "resuming without: " + problems[0]);
  // --new on a broken rig: refused, and the run it would have superseded is left as it was.
  EXPECT_THROW(station::start_run(s, config_with("B"), ask(true, std::nullopt, problems)),
               station::InputError);
  EXPECT_EQ(s.find_run(id)->state, station::RunState::running);
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
    station::start_run(s, c, ask());
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
  const auto d = station::start_run(s, station::parse_station_config(moved, "rig.toml"), ask());
  ASSERT_TRUE(d.resume.has_value());
  EXPECT_EQ(d.resume->id, id);
}
