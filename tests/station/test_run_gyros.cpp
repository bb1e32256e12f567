// The gyros of a run (station/daemon/run_gyros.hpp, issue 35): given at start, checked one line
// per problem before anything moves, stored with the run, kept by its resume.
#include <gtest/gtest.h>

#include <fstream>

#include "station/daemon/resume.hpp"
#include "station/daemon/run_start.hpp"
#include "station/store/sqlite.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::SlotGyro;
using station::testing_support::fresh_db;

/// A rig of two slots (nodes 1 and 2); `serials` the [[slot]] serial lines ("" for none).
station::StationConfig rig(const std::string& serial1, const std::string& serial2) {
  const auto line = [](const std::string& s) {
    return s.empty() ? std::string() : "serial = \"" + s + "\"\n";
  };
  return station::parse_station_config(
      "[station]\nlatitude_deg = 40\n[chamber]\nendpoint = \"tcp://127.0.0.1:502\"\n[can]\n"
      "transport = \"unix:/tmp/x.sock\"\n[[slot]]\nnode = 1\n" +
          line(serial1) + "[[slot]]\nnode = 2\n" + line(serial2),
      "rig.toml");
}

std::string parts_file() {
  const std::string path = ::testing::TempDir() + "gyros-parts.toml";
  std::ofstream(path) << "[part.GX-100]\nk1_dph_per_c = { max = 1.0 }\n";
  return path;
}

station::StartRequest ask(std::vector<SlotGyro> gyros, bool fresh = false) {
  station::StartRequest r{
      station::parse_protocol("name = \"p\"\n[[step]]\ntype = \"hold\"\nduration_s = 60\n",
                              "p.toml"),
      fresh,
      std::nullopt,
      {}};
  r.gyros = std::move(gyros);
  return r;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

}  // namespace

TEST(RunGyros, TheSlotOptionIsNumberSerialAndPart) {
  EXPECT_EQ(station::parse_slot_gyro("1=SN-7,GX-100", "--slot"), (SlotGyro{1, "SN-7", "GX-100"}));
  EXPECT_EQ(station::parse_slot_gyro("12=SN-7", "--slot"), (SlotGyro{12, "SN-7", ""}));
  for (const std::string bad : {"SN-7", "0=SN", "x=SN", "-1=SN", "1=", "1=SN X", "1=SN,", "=SN",
                                "01=SN", "+1=SN", "1000=SN"}) {
    try {
      station::parse_slot_gyro(bad, "--slot");
      ADD_FAILURE() << bad << " was taken";
    } catch (const station::InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--slot '" + bad + "'", 0), 0u) << e.what();
    }
  }
}

TEST(RunGyros, EachProblemIsOneLineNamingTheSlot) {
  const auto c = rig("A", "B");
  const auto parts = parts_file();
  EXPECT_TRUE(station::gyro_problems(c, {{1, "S1", "GX-100"}, {2, "S2", ""}}, parts, true).empty());
  const auto missing = station::gyro_problems(c, {{3, "S3", ""}}, parts, true);
  ASSERT_EQ(missing.size(), 1u) << joined(missing);
  EXPECT_EQ(missing[0], "slot 3: the configuration rig.toml has slots 1..2");
  const auto twice = station::gyro_problems(c, {{1, "S1", ""}, {2, "S1", ""}}, parts, true);
  ASSERT_EQ(twice.size(), 1u) << joined(twice);
  EXPECT_EQ(twice[0], "slot 2 (node 2): serial 'S1' is on slot 1 as well");
  // A serial given on one slot that the configuration's default names on another.
  const auto default_clash = station::gyro_problems(c, {{1, "B", ""}}, parts, true);
  ASSERT_EQ(default_clash.size(), 1u) << joined(default_clash);
  EXPECT_EQ(default_clash[0], "slot 2 (node 2): serial 'B' is on slot 1 as well");
  const auto part = station::gyro_problems(c, {{1, "S1", "GX-9"}, {2, "S2", "GX-8"}}, parts, true);
  ASSERT_EQ(part.size(), 2u) << joined(part);
  EXPECT_EQ(part[0], "slot 1 (node 1): part 'GX-9' is not in " + parts + " (it has: GX-100)");
  const auto no_file = station::gyro_problems(c, {{1, "S1", "GX-100"}}, "", true);
  ASSERT_EQ(no_file.size(), 1u) << joined(no_file);
  EXPECT_NE(no_file[0].find("but no part file"), std::string::npos) << no_file[0];
  const auto text = station::gyro_problems(c, {{1, "S 1", ""}}, parts, true);
  ASSERT_EQ(text.size(), 1u) << joined(text);
  EXPECT_EQ(text[0].rfind("slot 1 (node 1): serial 'S 1': ", 0), 0u) << text[0];
}

TEST(RunGyros, AConfigurationWithoutSerialsNeedsThemAtStart) {
  const auto c = rig("", "");  // valid: the rig without gyros
  EXPECT_TRUE(c.slots[0].serial.empty());
  const auto none = station::gyro_problems(c, {{1, "S1", ""}}, "", true);
  ASSERT_EQ(none.size(), 1u) << joined(none);
  EXPECT_EQ(none[0],
            "slot 2 (node 2): no serial (the configuration names none): give it at start, e.g. "
            "--slot 2=SERIAL");
  // A resume keeps the run's own serials: nothing is missing there.
  EXPECT_TRUE(station::gyro_problems(c, {}, "", false).empty());
  station::Store s(fresh_db("gyros-no-serials"));
  EXPECT_THROW(station::start_run(s, c, ask({})), station::InputError);
  const auto plan = station::start_run(s, c, ask({{1, "S1", ""}, {2, "S2", ""}}));
  EXPECT_EQ(plan.config.slots[0].serial, "S1");
  EXPECT_EQ(plan.config.slots[1].serial, "S2");
}

TEST(RunGyros, ANewRunCarriesItsGyrosAndStoresWhereTheyCameFrom) {
  station::Store s(fresh_db("gyros-new"));
  const auto plan = station::start_run(s, rig("A", "B"), ask({{2, "S2", "GX-100"}}));
  ASSERT_FALSE(plan.resume.has_value());
  EXPECT_EQ(plan.config.slots[0].serial, "A");  // not given: the configuration's default
  EXPECT_EQ(plan.config.slots[1].serial, "S2");
  EXPECT_EQ(plan.config.slots[1].part, "GX-100");
  const auto id = s.create_run(
      {"p", "", "", "0", "rig", "", std::nullopt, 0.0, station::resolved_meaning_json(plan.config)},
      station::run_slots_of(plan.config));
  auto st =
      s.db().prepare("SELECT serial, gyro_source FROM run_slots WHERE run_id = ? ORDER BY slot");
  st.bind(1, id);
  std::vector<std::string> got;
  while (st.step()) got.push_back(st.column_text(0) + " " + st.column_text(1));
  EXPECT_EQ(got, (std::vector<std::string>{"A config", "S2 start"}));
}

TEST(RunGyros, AResumeKeepsItsOwnGyrosAndRefusesOthersInOneLine) {
  station::Store s(fresh_db("gyros-resume"));
  const auto first = station::start_run(s, rig("A", "B"), ask({{1, "S1", ""}, {2, "S2", ""}}));
  const auto id =
      s.create_run({"p", "name = \"p\"\n[[step]]\ntype = \"hold\"\nduration_s = 60\n", "", "0",
                    "rig", "", std::nullopt, 0.0, station::resolved_meaning_json(first.config)},
                   station::run_slots_of(first.config));
  // Without gyros: the stored ones, whatever the configuration's defaults say now.
  const auto again = station::start_run(s, rig("X", "Y"), ask({}));
  ASSERT_TRUE(again.resume.has_value());
  EXPECT_EQ(again.resume->id, id);
  EXPECT_EQ(again.config.slots[0].serial, "S1");
  EXPECT_EQ(again.config.slots[1].serial, "S2");
  // The same gyros given again: continues.
  EXPECT_TRUE(
      station::start_run(s, rig("A", "B"), ask({{1, "S1", ""}, {2, "S2", ""}})).resume.has_value());
  // Others: refused, one line naming each difference, the run untouched.
  try {
    station::start_run(s, rig("A", "B"), ask({{2, "S9", ""}, {1, "S1", "GX-100"}}));
    FAIL() << "a resume took other gyros";
  } catch (const station::InputError& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("run " + std::to_string(id) +
                       " was started with other gyros: slot 2 serial 'S2' -> 'S9'; slot 1 part "
                       "'' -> 'GX-100'; start a new run with --new"),
              std::string::npos)
        << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  }
  EXPECT_EQ(s.find_run(id)->state, station::RunState::running);
  // --new with gyros the check refuses leaves the old run as it was.
  EXPECT_THROW(station::start_run(s, rig("A", "B"), ask({{1, "A", ""}, {2, "A", ""}}, true)),
               station::InputError);
  EXPECT_EQ(s.find_run(id)->state, station::RunState::running);
}
