// Station configuration: examples load and match the JSON Schema; bad files name file, line, key.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "station/config/config.hpp"

namespace {

const std::string kSrc = STATION_SOURCE_DIR;

// Message of the InputError parsing `text` raises (empty if none).
std::string error_of(const std::string& text) {
  try {
    station::parse_station_config(text, "rig.toml");
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

const std::string kMinimal = R"([station]
latitude_deg = 39.9
[chamber]
endpoint = "tcp://127.0.0.1:502"
[can]
transport = "unix:/tmp/can.sock"
[[slot]]
node = 1
serial = "A"
)";

int run_validator(const std::string& files) {
  const std::string cmd = "/usr/bin/python3 " + kSrc + "/schemas/validate_toml.py " + kSrc +
                          "/schemas/station_config.schema.json " + files + " >/dev/null 2>&1";
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

}  // namespace

TEST(Config, ExamplesLoad) {
  const auto sim = station::load_station_config(kSrc + "/examples/station.toml");
  EXPECT_EQ(sim.slots.size(), 2u);
  EXPECT_DOUBLE_EQ(sim.latitude_deg, 39.9);
  EXPECT_TRUE(sim.turntable.has_value());
  const auto rtu = station::load_station_config(kSrc + "/examples/station_rtu.toml");
  EXPECT_EQ(rtu.chamber.model, "watlow_f4t");
  EXPECT_EQ(rtu.chamber.run_event, 2);
  ASSERT_EQ(rtu.chamber.overrides.size(), 1u);
  EXPECT_EQ(*rtu.chamber.overrides[0].address, 4180);
  EXPECT_NEAR(rtu.slots[1].enu.east, 1.0, 1e-12);  // heading 90 = east
  ASSERT_TRUE(rtu.gpio.has_value());
  ASSERT_NE(station::drivers::gpio::find_role(*rtu.gpio, "interlock"), nullptr);
  EXPECT_EQ(station::drivers::gpio::find_role(*rtu.gpio, "interlock")->line_name, "DOOR_SW");
  // One line map: the TOML's tower_red is the driver's role tower.red, slot 1's relay relay.1.
  ASSERT_NE(station::drivers::gpio::find_role(*rtu.gpio, "tower.red"), nullptr);
  ASSERT_NE(station::drivers::gpio::find_role(*rtu.gpio, "relay.1"), nullptr);
  EXPECT_EQ(station::drivers::gpio::find_role(*rtu.gpio, "relay.1")->line_name, "GYRO_PWR1");
}

TEST(Config, ExamplesMatchTheJsonSchema) {
  if (std::system("/usr/bin/python3 -c 'import jsonschema, tomllib' >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "python3-jsonschema not installed (scripts/dev installs it)";
  }
  EXPECT_EQ(run_validator(kSrc + "/examples/station.toml " + kSrc + "/examples/station_rtu.toml"),
            0);
  // The validator must be able to fail: a config with an unknown key and a bad node.
  const std::string bad = testing::TempDir() + "bad_schema.toml";
  std::ofstream(bad) << kMinimal << "colour = \"red\"\n";
  EXPECT_EQ(run_validator(bad), 1);
}

// fuzz_station_config / fuzz_protocol: toml++ quotes what it saw ("expected 'inf', saw 'i\n2'"),
// newline included, so a syntax error printed as two lines. Every InputError is one line.
TEST(Config, ASyntaxErrorQuotingANewlineIsStillOneLine) {
  const auto e = error_of(kMinimal + "pulse_weight_arcsec =i\n2x. 5as = \"up\"\n");
  EXPECT_EQ(e.rfind("rig.toml:", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  const auto k = error_of(kMinimal + "\"odd\\nkey\" = 1\n");
  EXPECT_EQ(k.find('\n'), std::string::npos) << k;
  EXPECT_NE(k.find("odd\\nkey"), std::string::npos) << k;
}

TEST(Config, MinimalFileGetsDefaults) {
  const auto c = station::parse_station_config(kMinimal, "rig.toml");
  EXPECT_EQ(c.chamber.model, "generic_plc");
  EXPECT_DOUBLE_EQ(c.slots[0].pulse_weight_arcsec, 1.5);
  EXPECT_DOUBLE_EQ(c.limits.max_ramp_c_per_min, 3.0);
  EXPECT_DOUBLE_EQ(c.limits.air_margin_c, 5.0);
  EXPECT_FALSE(c.turntable.has_value());
}

TEST(Config, UnknownKeyNamesLineAndKey) {
  const auto msg = error_of(kMinimal + "colour = \"red\"\n");
  EXPECT_NE(msg.find("rig.toml:10: key 'slot[0].colour': unknown key"), std::string::npos) << msg;
}

TEST(Config, WrongTypeAndRange) {
  std::string t = kMinimal;
  t.replace(t.find("39.9"), 4, "\"north\"");
  EXPECT_NE(error_of(t).find("rig.toml:2: key 'station.latitude_deg': expected a number"),
            std::string::npos)
      << error_of(t);
  std::string n = kMinimal;
  n.replace(n.find("node = 1"), 8, "node = 40");
  EXPECT_NE(error_of(n).find("rig.toml:8: key 'slot[0].node': CAN node must be 1..16"),
            std::string::npos)
      << error_of(n);
}

TEST(Config, NonFiniteNumbersAreRejected) {
  std::string t = kMinimal;
  t.replace(t.find("39.9"), 4, "nan");
  EXPECT_NE(error_of(t).find("rig.toml:2: key 'station.latitude_deg': must be a finite number"),
            std::string::npos)
      << error_of(t);
  const auto margin =
      station::parse_station_config(kMinimal + "[limits]\nair_margin_c = 2.5\n", "rig.toml");
  EXPECT_DOUBLE_EQ(margin.limits.air_margin_c, 2.5);
  EXPECT_NE(error_of(kMinimal + "[limits]\nair_margin_c = -1\n").find("key 'limits.air_margin_c'"),
            std::string::npos)
      << error_of(kMinimal + "[limits]\nair_margin_c = -1\n");
  EXPECT_NE(error_of(kMinimal + "[limits]\nmax_setpoint_c = inf\n").find("must be a finite number"),
            std::string::npos);
}

TEST(Config, BadEndpointPresetAndTransport) {
  std::string e = kMinimal;
  e.replace(e.find("tcp://127.0.0.1:502"), 19, "tcp://127.0.0.1:99999");
  EXPECT_NE(error_of(e).find("rig.toml:4: key 'chamber.endpoint'"), std::string::npos)
      << error_of(e);
  EXPECT_NE(error_of(kMinimal + "[chamber]\n").find("rig.toml"), std::string::npos);
  std::string p = kMinimal;
  p.insert(p.find("[can]"), "preset = \"acme\"\n");
  EXPECT_NE(error_of(p).find("key 'chamber.preset': unknown chamber model 'acme' (known: "
                             "generic_plc, watlow_f4, watlow_f4t"),
            std::string::npos)
      << error_of(p);
  // An ASCII dialect takes an ASCII endpoint, and has no register points to override.
  std::string a = kMinimal;
  a.insert(a.find("[can]"), "model = \"espec_p300\"\n");
  EXPECT_NO_THROW(station::parse_station_config(a, "rig.toml"));
  std::string rtu_p300 = a;
  rtu_p300.replace(rtu_p300.find("tcp://127.0.0.1:502"), 19, "rtu:/dev/ttyS0");
  EXPECT_NE(error_of(rtu_p300).find("key 'chamber.endpoint'"), std::string::npos)
      << error_of(rtu_p300);
  // Issue 7, house: the turntable's preset was accepted and then ignored.
  const std::string table = kMinimal + "[turntable]\nendpoint = \"tcp://127.0.0.1:503\"\n";
  EXPECT_NO_THROW(station::parse_station_config(table + "preset = \"default\"\n", "rig.toml"));
  EXPECT_NE(error_of(table + "preset = \"acme\"\n")
                .find("key 'turntable.preset': unknown turntable model 'acme'"),
            std::string::npos)
      << error_of(table + "preset = \"acme\"\n");
  std::string c = kMinimal;
  c.replace(c.find("unix:/tmp/can.sock"), 18, "carrier-pigeon:1");
  EXPECT_NE(error_of(c).find("rig.toml:6: key 'can.transport'"), std::string::npos) << error_of(c);
}

TEST(Config, OverrideOfAnUnknownPointIsRejected) {
  std::string o = kMinimal;
  o.insert(o.find("[can]"), "[[chamber.point]]\nname = \"humidity\"\naddress = 7\n");
  EXPECT_NE(error_of(o).find("humidity"), std::string::npos) << error_of(o);
}

TEST(Config, DuplicateSerialAndMissingTables) {
  EXPECT_NE(error_of(kMinimal + "[[slot]]\nnode = 2\nserial = \"A\"\n").find("serial used twice"),
            std::string::npos);
  EXPECT_NE(error_of("[station]\nlatitude_deg = 1\n").find("missing [chamber] table"),
            std::string::npos);
  EXPECT_NE(error_of("[station\n").find("rig.toml:1:"), std::string::npos)
      << error_of("[station\n");
}

// Issue 34 point 10: a NUL, a newline or a bidirectional override in a configured serial was
// accepted (221 samples stored, no fit; PostgreSQL kept "GX"). The text rule
// (station/common/text_rule.hpp) refuses it at the key, naming the character and its position.
TEST(Config, IdentifiersFollowTheTextRuleNamingKeyCharacterAndPosition) {
  const auto with_serial = [](const std::string& toml_value) {
    std::string t = kMinimal;
    t.replace(t.find("serial = \"A\""), 12, "serial = \"" + toml_value + "\"");
    return t;
  };
  const std::vector<std::pair<std::string, std::string>> serials{
      {"GX\\u0000-1", "rig.toml:9: key 'slot[0].serial': U+0000 at character 3 (byte 2)"},
      {"GX\\n1", "rig.toml:9: key 'slot[0].serial': U+000A at character 3 (byte 2)"},
      {"GX\\u202E1", "rig.toml:9: key 'slot[0].serial': U+202E at character 3 (byte 2)"},
      {"GX 1", "rig.toml:9: key 'slot[0].serial': U+0020 at character 3 (byte 2)"},
      {"X;part=Y", "rig.toml:9: key 'slot[0].serial': U+003B at character 2 (byte 1)"},
      {"=HYPERLINK(1)", "rig.toml:9: key 'slot[0].serial': U+003D at character 1 (byte 0)"},
      {std::string(65, 'A'), "rig.toml:9: key 'slot[0].serial': 65 bytes"},
  };
  for (const auto& [value, says] : serials)
    EXPECT_NE(error_of(with_serial(value)).find(says), std::string::npos)
        << value << ": " << error_of(with_serial(value));
  // The longest identifier and every punctuation it allows still load.
  EXPECT_EQ(error_of(with_serial("G" + std::string(63, 'x'))), "");
  EXPECT_EQ(error_of(with_serial("RLG-2311_0043.a:b/c+d#e")), "");
  const std::string part = kMinimal + "part = \"P\\u2066N\"\n";
  EXPECT_NE(error_of(part).find("rig.toml:10: key 'slot[0].part': U+2066 at character 2"),
            std::string::npos)
      << error_of(part);
  std::string name = kMinimal;
  name.insert(name.find("latitude_deg"), "name = \"line\\r2\"\n");
  EXPECT_NE(error_of(name).find("rig.toml:2: key 'station.name': U+000D at character 5"),
            std::string::npos)
      << error_of(name);
  // The JSON Schema says the same.
  const std::string bad = ::testing::TempDir() + "bidi-serial.toml";
  std::ofstream(bad) << with_serial("GX\\u202E1");
  EXPECT_EQ(run_validator(bad), 1);
}
