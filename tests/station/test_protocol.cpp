// Protocol files: shipped protocols parse and match the schema; bad files name file, line, key;
// the runner walks steps, ramps on the station's profile and resumes where it was.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <string>

#include "station/config/protocol.hpp"
#include "station/daemon/protocol_runner.hpp"

namespace {

const std::string kSrc = STATION_SOURCE_DIR;

std::string error_of(const std::string& text) {
  try {
    station::parse_protocol(text, "p.toml");
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(Protocol, ShippedProtocolsLoadByName) {
  for (const auto& name : station::builtin_protocol_names()) {
    SCOPED_TRACE(name);
    const auto p = station::load_protocol(name);
    EXPECT_EQ(p.name, name);
    EXPECT_FALSE(p.steps.empty());
  }
  const auto paper = station::load_protocol("paper");
  // Cool 65 C at 60 C/h, heat 110 C at 10 C/h, return 45 C at 60 C/h: 1.083 + 11 + 0.75 h.
  EXPECT_NEAR(paper.nominal_duration_s(25.0) / 3600.0, 12.833, 0.01);
}

TEST(Protocol, ShippedProtocolsMatchTheJsonSchema) {
  if (std::system("/usr/bin/python3 -c 'import jsonschema, tomllib' >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "python3-jsonschema not installed (scripts/dev installs it)";
  }
  const std::string base = "/usr/bin/python3 " + kSrc + "/schemas/validate_toml.py " + kSrc +
                           "/schemas/protocol.schema.json ";
  EXPECT_EQ(std::system((base + kSrc + "/station/protocols/*.toml >/dev/null").c_str()), 0);
  const std::string bad = testing::TempDir() + "bad_protocol.toml";
  FILE* f = std::fopen(bad.c_str(), "w");
  std::fputs("name = \"x\"\n[[step]]\ntype = \"hold\"\n", f);  // hold without duration_s
  std::fclose(f);
  EXPECT_NE(std::system((base + bad + " >/dev/null").c_str()), 0);
}

TEST(Protocol, BadFilesNameLineAndKey) {
  EXPECT_NE(error_of("name = \"x\"\n[[step]]\ntype = \"bake\"\n")
                .find("p.toml:3: key 'step[0].type': unknown step type 'bake'"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\n[[step]]\ntype = \"hold\"\nduration_s = 5\nspeed = 3\n")
                .find("p.toml:5: key 'step[0].speed': unknown key"),
            std::string::npos);
  EXPECT_NE(
      error_of(
          "name = \"x\"\n[[step]]\ntype = \"set_temperature\"\nramp_c_per_h = -1\nsetpoint_c = 1\n")
          .find("p.toml:4: key 'step[0].ramp_c_per_h': -1 is outside 0..6000 C/h"),
      std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\n[[step]]\ntype = \"record_stop\"\n")
                .find("record_stop while the record window is closed"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\n").find("needs at least one [[step]]"), std::string::npos);
  EXPECT_THROW(station::load_protocol("/no/such/protocol.toml"), station::InputError);
}

// Issue 19 item 13: an integer too large for a double was read as 0 s (a hold of
// 9223372036854775807 s ended at once); a ramp that would take longer than a step may is refused
// with file, line and key, whether its span is fixed by the protocol or by the station's limits.
TEST(Protocol, StepsLongerThanAWeekAreRefusedWithFileLineAndKey) {
  EXPECT_NE(error_of("name = \"x\"\n[[step]]\ntype = \"hold\"\nduration_s = 9223372036854775807\n")
                .find("p.toml:4: key 'step[0].duration_s': 9.22337e+18 s is longer than"),
            std::string::npos);
  const std::string two_ramps =
      "name = \"x\"\n[[step]]\ntype = \"set_temperature\"\nsetpoint_c = -40\n"
      "[[step]]\ntype = \"set_temperature\"\nsetpoint_c = 70\nramp_c_per_h = ";
  // 110 C at 1 C/h is 4.6 days: allowed. At 0.5 C/h, 9.2 days: refused at parse, span known.
  EXPECT_EQ(error_of(two_ramps + "1\n"), "");
  EXPECT_NE(
      error_of(two_ramps + "0.5\n")
          .find("p.toml:8: key 'step[1].ramp_c_per_h': 0.5 C/h over 110 C takes 9.16667 days"),
      std::string::npos)
      << error_of(two_ramps + "0.5\n");
  // The first ramp starts wherever the chamber is: judged at run start over the limits.
  const auto first = station::parse_protocol(
      "name = \"x\"\n[[step]]\ntype = \"set_temperature\"\nsetpoint_c = -40\n"
      "ramp_c_per_h = 1e-300\n",
      "p.toml");
  try {
    first.check_step_times(-55.0, 85.0);
    ADD_FAILURE() << "a ramp of 1e-300 C/h was accepted";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.toml:5: key 'step[0].ramp_c_per_h': 1e-300 C/h over "
                                         "125 C takes"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(station::load_protocol("paper").check_step_times(-55.0, 85.0));
}

TEST(ProtocolRunner, RampsAlongTheStationsProfileAndWaitsForTheAir) {
  const auto p = station::parse_protocol(
      "name = \"t\"\n[[step]]\ntype = \"set_temperature\"\nsetpoint_c = 35.0\nramp_c_per_h = 36.0\n"
      "tolerance_c = 0.5\n[[step]]\ntype = \"record_start\"\n",
      "t.toml");
  station::RunProgress start;
  start.start_temp_c = 25.0;
  station::ProtocolRunner r(p, start);
  station::Observation obs;
  obs.air_c = 25.0;
  auto a = r.tick(obs);  // t = 0: the ramp starts at 25 C, controller set to a step, enabled
  ASSERT_TRUE(a.chamber.has_value());
  EXPECT_DOUBLE_EQ(*a.chamber->setpoint_c, 25.0);
  EXPECT_TRUE(a.chamber->run.value_or(false));
  obs.t_s = 500;  // 36 C/h * 500 s = 5 C along
  a = r.tick(obs);
  ASSERT_TRUE(a.chamber.has_value());
  EXPECT_NEAR(*a.chamber->setpoint_c, 30.0, 1e-12);
  EXPECT_FALSE(a.chamber->run.has_value());  // later ramp commands only move the setpoint
  obs.t_s = 501;                             // moved 0.01 C: below the 0.05 C write threshold
  EXPECT_FALSE(r.tick(obs).chamber.has_value());
  obs.t_s = 1000;  // ramp complete, air not there yet
  a = r.tick(obs);
  EXPECT_NEAR(*a.chamber->setpoint_c, 35.0, 1e-12);
  EXPECT_EQ(r.progress().step_index, 0);
  obs.t_s = 1100;
  obs.air_c = 34.6;
  r.tick(obs);
  EXPECT_TRUE(r.done());
  EXPECT_TRUE(r.progress().recording);
  EXPECT_DOUBLE_EQ(*r.progress().record_start_s, 1100.0);
}

TEST(ProtocolRunner, ResumedRampContinuesFromTheStoredStepStart) {
  const auto p = station::parse_protocol(
      "name = \"t\"\n[[step]]\ntype = \"set_temperature\"\nsetpoint_c = -40.0\n[[step]]\n"
      "type = \"set_temperature\"\nsetpoint_c = 70.0\nramp_c_per_h = 10.0\n",
      "t.toml");
  station::RunProgress resumed;
  resumed.step_index = 1;
  resumed.step_started_s = 4000;
  resumed.start_temp_c = 25.0;
  station::ProtocolRunner r(p, resumed);
  station::Observation obs;
  obs.t_s = 4000 + 7200;  // two hours into the 10 C/h ramp from -40 C
  obs.air_c = -20.5;
  const auto a = r.tick(obs);
  ASSERT_TRUE(a.chamber.has_value());
  EXPECT_NEAR(*a.chamber->setpoint_c, -20.0, 1e-12);
}

TEST(ProtocolRunner, SoakNeedsChamberAndGyrosStableForTheDuration) {
  const auto p = station::parse_protocol(
      "name = \"t\"\n[[step]]\ntype = \"set_temperature\"\nsetpoint_c = 0.0\nwait = false\n"
      "[[step]]\ntype = \"soak\"\ntolerance_c = 0.5\nduration_s = 100\n",
      "t.toml");
  station::ProtocolRunner r(p, {});
  station::Observation obs;
  obs.air_c = 0.1;
  obs.gyro_temps_c = {3.0};  // gyro still warm
  r.tick(obs);
  EXPECT_EQ(r.progress().step_index, 1);
  for (double t = 1; t <= 200; ++t) {
    obs.t_s = t;
    obs.gyro_temps_c = {t < 50 ? 3.0 : 0.3};  // stable from t = 50
    r.tick(obs);
    EXPECT_EQ(r.done(), t >= 150) << t;
  }
}
