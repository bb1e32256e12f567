// Resume decisions: only the same rig continues a run, with its stored protocol; --new and
// mismatches mark the old run aborted.
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
  return s.create_run({"p", protocol, "", "0", "rig", "", std::nullopt, 0.0},
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
  EXPECT_EQ(s.find_run(first)->state, "aborted");
  const auto second = start_run(s);
  EXPECT_FALSE(station::decide_resume(s, config_with("C"), false, true).run.has_value());
  EXPECT_EQ(s.find_run(second)->state, "aborted");
  EXPECT_EQ(s.events(second).back().rfind("aborted: run", 0), 0u);
}
