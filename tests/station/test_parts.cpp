// Part files: the shipped example loads and matches its JSON Schema; each bad file is one line
// naming the file, the line and the key; slots naming parts are checked against the file.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "station/parts/part_file.hpp"

namespace {

const std::string kSrc = STATION_SOURCE_DIR;
const std::string kExample = kSrc + "/station/parts/example_parts.toml";

// Message of the InputError parsing `text` as parts.toml raises (empty if none).
std::string error_of(const std::string& text) {
  try {
    station::parse_part_file(text, "parts.toml");
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

const std::string kGood = R"([part."GX-1"]
description = "test part"
B0_dph = { min = -0.2, max = 0.2 }
k1_dph_per_c = { max = 3e-3 }
k0_dph_per_c = { min = -0.06, max = 0.06 }
max_std_after_dph = 0.01
max_std_ratio = 0.5
max_adev_floor_dph = 0.02
min_complete_bins = 40
max_k1_se_dph_per_c = 1e-4
max_k0_se_dph_per_c = 2e-3
)";

const std::string kConfig = R"([station]
latitude_deg = 39.9
[chamber]
endpoint = "tcp://127.0.0.1:502"
[can]
transport = "unix:/tmp/can.sock"
[[slot]]
node = 1
serial = "A"
[[slot]]
node = 2
serial = "B"
part = "GX-1"
)";

// slot_part_limits' error (empty if none) for kConfig (+ `extra` in [station]) and `parts`.
std::string slot_error(const std::string& parts_path, const std::string& config = kConfig) {
  try {
    station::slot_part_limits(station::parse_station_config(config, "rig.toml"), parts_path);
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST(Parts, AGoodFileReadsEveryLimit) {
  const auto f = station::parse_part_file(kGood, "parts.toml");
  ASSERT_EQ(f.parts.size(), 1u);
  const auto& p = f.parts.at("GX-1");
  EXPECT_EQ(p.number, "GX-1");
  EXPECT_EQ(p.description, "test part");
  EXPECT_DOUBLE_EQ(*p.b0_dph.min, -0.2);
  EXPECT_FALSE(p.k1_dph_per_c.min.has_value());
  EXPECT_DOUBLE_EQ(*p.k1_dph_per_c.max, 3e-3);
  EXPECT_DOUBLE_EQ(*p.k0_dph_per_c.max, 0.06);
  EXPECT_DOUBLE_EQ(*p.max_std_after_dph, 0.01);
  EXPECT_DOUBLE_EQ(*p.max_std_ratio, 0.5);
  EXPECT_DOUBLE_EQ(*p.max_adev_floor_dph, 0.02);
  EXPECT_EQ(*p.min_complete_bins, 40);
  EXPECT_DOUBLE_EQ(*p.max_k1_se_dph_per_c, 1e-4);
  EXPECT_DOUBLE_EQ(*p.max_k0_se_dph_per_c, 2e-3);
}

TEST(Parts, LimitsSurviveTheJsonSnapshotStoredWithARun) {
  const auto p = station::parse_part_file(kGood, "parts.toml").parts.at("GX-1");
  const auto back = station::part_limits_from_json(station::part_limits_json(p));
  EXPECT_EQ(station::part_limits_json(back), station::part_limits_json(p));
  EXPECT_FALSE(back.k1_dph_per_c.min.has_value());
  EXPECT_EQ(*back.min_complete_bins, 40);
}

// Issue 32: the part's model and noise survive the run's snapshot, and are what a fit uses.
TEST(Parts, TheModelAndNoiseSurviveTheSnapshot) {
  const auto p =
      station::parse_part_file(kGood +
                                   "model = \"dT,dT2,gradT\"\n[part.\"GX-1\".noise]\n"
                                   "arw_deg_rt_h = 0.003\nrrw_dph_rt_h = 0\ntrust_factor = 1.5\n",
                               "parts.toml")
          .parts.at("GX-1");
  ASSERT_TRUE(p.model && p.noise);
  EXPECT_EQ(*p.model, "dT,dT2,gradT");
  EXPECT_EQ(*p.noise->arw_deg_rt_h, 0.003);
  EXPECT_EQ(*p.noise->rrw_dph_rt_h, 0.0);
  EXPECT_FALSE(p.noise->bias_instability_dph);
  EXPECT_EQ(p.noise->trust_factor, 1.5);
  const auto back = station::part_limits_from_json(station::part_limits_json(p));
  EXPECT_EQ(station::part_limits_json(back), station::part_limits_json(p));
}

TEST(Parts, EachBadFileIsOneLineNamingFileLineAndKey) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases{
      {"[part.A]\nk2_dph_per_c = { max = 1 }\n",
       "parts.toml:2: key 'part.A.k2_dph_per_c': unknown key (allowed here: description, "},
      {"[part.A]\nk1_dph_per_c = { min = 2e-3, max = 1e-3 }\n",
       "parts.toml:2: key 'part.A.k1_dph_per_c.min': min 0.002 is above max 0.001"},
      {"[part.A]\nmax_std_ratio = \"small\"\n",
       "parts.toml:2: key 'part.A.max_std_ratio': expected a number"},
      {"[part.A]\nmin_complete_bins = 40.5\n",
       "parts.toml:2: key 'part.A.min_complete_bins': expected an integer"},
      {"[part.A]\nmin_complete_bins = 2\n",
       "parts.toml:2: key 'part.A.min_complete_bins': 2 is outside 3..52560"},
      {"[part.A]\nmax_std_after_dph = 0\n",
       "parts.toml:2: key 'part.A.max_std_after_dph': 0 must be above 0"},
      {"[part.A]\nB0_dph = { typical = 1 }\n",
       "parts.toml:2: key 'part.A.B0_dph.typical': unknown key (allowed here: min, max)"},
      {"[part.A]\nB0_dph = {}\n", "parts.toml:2: key 'part.A.B0_dph': give min, max or both"},
      {"[part.A]\nB0_dph = 0.1\n", "parts.toml:2: key 'part.A.B0_dph': expected a table"},
      {"[part]\nA = 3\n", "parts.toml:2: key 'part.A': expected a table"},
      {"[parts.A]\n", "parts.toml:1: key 'parts': unknown key (allowed here: part)"},
      {"", "parts.toml:1: key 'part': no [part.\"NUMBER\"] tables: the file names no part"},
      {"[part.A]\nmax_std_ratio = 0.5\nmax_std_ratio = 0.4\n", "parts.toml:3:"},
      // Issue 32: the part's model and noise.
      {"[part.A]\nmodel = \"dT,dT9\"\n", "parts.toml:2: key 'part.A.model': unknown term 'dT9'"},
      {"[part.A]\nmodel = \"dT,dTdt\"\n",
       "parts.toml:2: key 'part.A.model': term dTdt cannot be delivered"},
      {"[part.A]\nmodel = \"\"\n", "parts.toml:2: key 'part.A.model': "},
      {"[part.A.noise]\nrrw_dph_rt_h = 1e200\n",
       "parts.toml:2: key 'part.A.noise.rrw_dph_rt_h': 1e+200 is outside 0..1000000"},
      {"[part.A.noise]\narw_deg_rt_h = 0.003\ntrust_factor = 1.0000001\n",
       "parts.toml:3: key 'part.A.noise.trust_factor': 1.0000001 is outside 1.01..1000"},
      {"[part.A.noise]\narw_deg_rt_h = 0\n",
       "parts.toml:2: key 'part.A.noise.arw_deg_rt_h': 0 is outside (0..1000000"},
      {"[part.A.noise]\nrrw_dph_rt_h = -1e-4\n",
       "parts.toml:2: key 'part.A.noise.rrw_dph_rt_h': -0.0001 is outside 0..1000000"},
      {"[part.A.noise]\narw_deg_rt_h = 0.003\ntrust_factor = 1\n",
       "parts.toml:3: key 'part.A.noise.trust_factor': 1 is outside 1.01..1000"},
      {"[part.A.noise]\nK = 1e-4\n", "parts.toml:2: key 'part.A.noise.K': unknown key"},
      {"[part.A.noise]\ntrust_factor = 3\n",
       "parts.toml:1: key 'part.A.noise': give arw_deg_rt_h, bias_instability_dph or rrw_dph_rt_h"},
  };
  for (const auto& c : cases) {
    const auto e = error_of(c.text);
    EXPECT_EQ(e.rfind(c.expected, 0), 0u) << "file:\n" << c.text << "\ngave: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(Parts, AMissingFileIsOneLineNamingIt) {
  try {
    station::load_part_file("/nonexistent/parts.toml");
    FAIL() << "a missing part file was accepted";
  } catch (const station::InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/parts.toml: cannot open the part file");
  }
}

TEST(Parts, SlotsGetTheirPartsLimitsBySerial) {
  const auto path = write_temp("slots_parts.toml", kGood);
  const auto config = station::parse_station_config(kConfig, "rig.toml");
  EXPECT_EQ(config.slots[1].part, "GX-1");
  EXPECT_EQ(config.slots[1].part_line, 13u);
  const auto limits = station::slot_part_limits(config, path);
  ASSERT_EQ(limits.size(), 1u);  // slot A names no part: no verdict for it
  EXPECT_EQ(limits.at("B").number, "GX-1");
}

TEST(Parts, AConfigKeyNamesThePartFileRelativeToTheConfig) {
  const std::string dir = testing::TempDir();
  write_temp("rel_parts.toml", kGood);
  std::string config = kConfig;
  config.insert(config.find("[chamber]"), "parts = \"rel_parts.toml\"\n");
  const auto c = station::parse_station_config(config, dir + "rig.toml");
  EXPECT_EQ(c.parts_path, dir + "rel_parts.toml");
  EXPECT_EQ(station::slot_part_limits(c, "").at("B").number, "GX-1");
}

TEST(Parts, ASlotNamingAnUnknownPartIsOneLineNamingConfigLineAndKey) {
  const auto path = write_temp("unknown_part.toml", kGood);
  std::string config = kConfig;
  config.replace(config.find("GX-1"), 4, "GX-9");
  EXPECT_EQ(slot_error(path, config),
            "rig.toml:13: key 'slot[1].part': part 'GX-9' is not in " + path + " (it has: GX-1)");
}

TEST(Parts, ASlotNamingAPartWithNoPartFileIsRefused) {
  EXPECT_EQ(slot_error(""),
            "rig.toml:13: key 'slot[1].part': part 'GX-1' but no part file (give [station] parts "
            "or --parts FILE)");
}

TEST(Parts, TheConfigRejectsAnEmptyPart) {
  std::string config = kConfig;
  config.replace(config.find("\"GX-1\""), 6, "\"\"");
  try {
    station::parse_station_config(config, "rig.toml");
    FAIL() << "an empty part number was accepted";
  } catch (const station::InputError& e) {
    EXPECT_STREQ(e.what(), "rig.toml:13: key 'slot[1].part': must not be empty");
  }
}

TEST(Parts, TheShippedExampleLoadsAndMatchesTheJsonSchema) {
  const auto f = station::load_part_file(kExample);
  EXPECT_GE(f.parts.size(), 2u);
  if (std::system("/usr/bin/python3 -c 'import jsonschema, tomllib' >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "python3-jsonschema not installed (scripts/dev installs it)";
  }
  const auto validate = [](const std::string& file) {
    const std::string cmd = "/usr/bin/python3 " + kSrc + "/schemas/validate_toml.py " + kSrc +
                            "/schemas/parts.schema.json " + file + " >/dev/null 2>&1";
    const int raw = std::system(cmd.c_str());
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  };
  EXPECT_EQ(validate(kExample), 0);
  // The validator must be able to fail: an unknown key.
  EXPECT_EQ(validate(write_temp("bad_parts_schema.toml", kGood + "colour = \"red\"\n")), 1);
}
