// Issue 36's hostile review, messages: a value compared with a limit is printed as written, with
// enough digits to be told from the limit ("1000.0001 is outside 0..1000", never "1000 is
// outside 0..1000": `{:g}` rounded to six digits), in the configuration's range messages, the
// part file's, the start's turntable check and the acceptance verdict.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "station/acceptance/acceptance_verdict.hpp"
#include "station/common/input_error.hpp"
#include "station/common/number_text.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/acceptance_runner.hpp"
#include "station/parts/part_file.hpp"

namespace {

template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const station::InputError& e) {
    return e.what();
  }
  return "";
}

std::string protocol_error(const std::string& step_body) {
  return error_of([&] {
    station::parse_protocol(
        "name = \"p\"\n[[step]]\n" + step_body + "[[step]]\ntype = \"lock_turntable\"\n", "p.toml");
  });
}

}  // namespace

TEST(LimitMessages, AValueBesideItsLimitHasTheDigitsToTellThemApart) {
  EXPECT_EQ(station::as_written(1000.0001), "1000.0001");
  EXPECT_EQ(station::as_written(0.1), "0.1");
  EXPECT_EQ(station::beside_limit(1000.0001, 1000, 7), "1000.0001");
  EXPECT_EQ(station::beside_limit(999.99999, 1000, 4), "999.99999");
  EXPECT_EQ(station::beside_limit(1234.56, 1000, 4), "1235");  // far from it: 4 digits
  EXPECT_EQ(station::beside_limit(-1000.0004, -1000, 4), "-1000.0004");
  // Rounding that lands on the other side of the limit is not taken either ("0.01" and
  // "0.0100004" read below a limit the value is above).
  EXPECT_EQ(station::beside_limit(0.01000044, 0.010000435, 5), "0.01000044");
  EXPECT_EQ(station::beside_limit(0.0100004999, 0.0100005, 6), "0.0100004999");
}

TEST(LimitMessages, TheProtocolsRangesPrintTheValueAsWritten) {
  const std::string e =
      protocol_error("type = \"set_temperature\"\nramp_c_per_h = 6000.0001\nsetpoint_c = 1\n");
  EXPECT_NE(e.find("p.toml:4: key 'step[0].ramp_c_per_h': 6000.0001 is outside 0..6000 C/h"),
            std::string::npos)
      << e;
  const std::string r = protocol_error("type = \"rate_ladder\"\nrates_dps = [1, 1000.0001]\n");
  EXPECT_NE(r.find("entry 1: 1000.0001 is outside 0..1000 deg/s"), std::string::npos) << r;
  // The acceptance steps' own bounds ("2 s is shorter than 2 s", "100 and 100 are one rate").
  const std::string s =
      protocol_error("type = \"rate_ladder\"\nrates_dps = [10, 20]\nsettle_s = 1.9999999\n");
  EXPECT_NE(s.find("1.9999999 s is shorter than 2 s"), std::string::npos) << s;
  const std::string two = protocol_error("type = \"rate_ladder\"\nrates_dps = [100, 100.0001]\n");
  EXPECT_NE(two.find("entries 0 and 1: 100 and 100.0001 are one rate"), std::string::npos) << two;
}

TEST(LimitMessages, ThePartFilesLimitsPrintTheValueAsWritten) {
  const std::string e = error_of([] {
    station::parse_part_file("[part.A]\nk1_dph_per_c = { min = 1000.0001, max = 1000 }\n",
                             "parts.toml");
  });
  EXPECT_NE(e.find("min 1000.0001 is above max 1000"), std::string::npos) << e;
}

TEST(LimitMessages, TheTurntableCheckPrintsTheRateAsWritten) {
  const auto p = station::parse_protocol(
      "name = \"p\"\n[[step]]\ntype = \"rate_ladder\"\nrates_dps = [10, 500.0001]\n[[step]]\ntype "
      "= \"lock_turntable\"\n",
      "p.toml");
  const auto c = station::parse_station_config(
      "[station]\nlatitude_deg = 39.9\n[chamber]\nendpoint = \"tcp://127.0.0.1:1502\"\n"
      "[turntable]\nendpoint = \"tcp://127.0.0.1:1503\"\n[can]\ntransport = "
      "\"unix:/tmp/x.can\"\n[[slot]]\nnode = 1\nserial = \"A\"\n",
      "rig.toml");
  const std::string e = error_of([&] { station::check_acceptance_rig(p, c, true); });
  EXPECT_NE(e.find("rates_dps entry 1: 500.0001 deg/s is beyond the turntable's rate limit 500 "
                   "deg/s"),
            std::string::npos)
      << e;
}

TEST(LimitMessages, TheVerdictTellsAFigureFromTheLimitItFailed) {
  auto serials = nlohmann::json::parse(R"([{"serial": "A", "ladders": [
      {"label": "room", "ok": true, "sf_pulse_per_arcsec": 0.66670001,
       "nonlinearity_max_ppm_fs": 100.00001}],
      "positions": [],
      "turn_on": {"ok": true, "repeatability_dph": 0.004, "max_warmup_s": 1000.0001}}])");
  station::PartLimits part;
  part.number = "GX";
  part.acceptance = station::AcceptanceLimits{};
  part.acceptance->sf_pulse_per_arcsec.max = 0.6667;
  part.acceptance->max_nonlinearity_ppm_fs = 100;
  part.acceptance->max_warmup_s = 1000;
  station::judge_acceptance(serials, {{"A", part}});
  const auto& v = serials[0]["verdict"];
  EXPECT_FALSE(v["pass"].get<bool>());
  EXPECT_EQ(v["failed"], (nlohmann::json{"scale factor 0.66670001 pulse/arcsec above 0.6667",
                                         "nonlinearity at 'room' 100.00001 ppm FS above 100",
                                         "warm-up 1000.0001 s above 1000"}))
      << v.dump();
}
