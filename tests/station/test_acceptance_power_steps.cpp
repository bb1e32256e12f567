// Issue 36: a protocol with two power_cycles steps has each one analysed (it was only the last):
// figures per step in "turn_on_steps", the first step's in "turn_on" (what the report, the store
// and the fleet carry), every step judged.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "station/acceptance/acceptance_json.hpp"
#include "station/acceptance/acceptance_verdict.hpp"
#include "station/sim/sim_run.hpp"
#include "tests/station/temp_db.hpp"

TEST(AcceptancePowerSteps, EachPowerCyclesStepHasItsOwnFigures) {
  const std::string power =
      "[[step]]\ntype = \"power_cycles\"\nlabel = \"LABEL\"\ncycles = 2\n"
      "off_s = 60\non_s = 600\n";
  std::string text = "name = \"two_power_steps\"\ndescription = \"two blocks of turn-ons\"\n";
  text += "[[step]]\ntype = \"lock_turntable\"\nposition_deg = 0.0\n";
  for (const char* label : {"first block", "second block"}) {
    std::string p = power;
    p.replace(p.find("LABEL"), 5, label);
    text += p;
  }
  const std::string path = ::testing::TempDir() + "two-power-" + std::to_string(getpid()) + ".toml";
  std::ofstream(path) << text;
  station::SimRunOptions o;
  o.db_path = station::testing_support::fresh_db("acceptance_power_steps");
  o.protocol = path;
  o.progress = false;
  o.fresh = true;
  o.gyros = 2;
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  for (const auto& s : r["acceptance"]) {
    ASSERT_TRUE(s.contains("turn_on_steps")) << s.dump();
    const auto& steps = s["turn_on_steps"];
    ASSERT_EQ(steps.size(), 2u);
    EXPECT_EQ(steps[0]["step_index"], 1);
    EXPECT_EQ(steps[1]["step_index"], 2);
    EXPECT_EQ(steps[0]["label"], "first block");
    EXPECT_EQ(steps[1]["label"], "second block");
    for (const auto& t : steps) {
      ASSERT_TRUE(t["ok"].get<bool>()) << t.dump();
      EXPECT_EQ(t["turn_ons"], 2);
      EXPECT_TRUE(t.contains("true"));  // the simulator's truth per step
    }
    // "turn_on" is the first step's, not the last's.
    EXPECT_EQ(s["turn_on"]["biases_dph"], steps[0]["biases_dph"]);
    EXPECT_NE(s["turn_on"]["biases_dph"], steps[1]["biases_dph"]);
  }
}

// The shortest powered times the parser takes, and ones whose last third holds one bin's centre
// (250 s: bins to 240 s, centres 150 and 210 s, third 167..250 s; 330 s: third 220..330 s, centres
// 210 and 270 s): each turn-on analysed from at least its last two whole bins (they were refused:
// "final window 220..330 s holds 1 bins").
TEST(AcceptancePowerSteps, AShortPoweredTimeStillHasAFinalValue) {
  for (const int on_s : {240, 250, 330}) {
    SCOPED_TRACE(on_s);
    const std::string text =
        "name = \"short_on\"\ndescription = \"short turn-ons\"\n[[step]]\ntype = "
        "\"lock_turntable\"\nposition_deg = 0.0\n[[step]]\ntype = \"power_cycles\"\ncycles = "
        "2\noff_s = 60\non_s = " +
        std::to_string(on_s) + "\n";
    const std::string path = ::testing::TempDir() + "short-on-" + std::to_string(on_s) + "-" +
                             std::to_string(getpid()) + ".toml";
    std::ofstream(path) << text;
    station::SimRunOptions o;
    o.db_path = station::testing_support::fresh_db("acceptance_short_on_" + std::to_string(on_s));
    o.protocol = path;
    o.progress = false;
    o.fresh = true;
    o.gyros = 1;
    const auto r = station::run_simulated(o);
    ASSERT_EQ(r["state"], "completed") << r.dump();
    const auto& t = r["acceptance"][0]["turn_on"];
    ASSERT_TRUE(t["ok"].get<bool>()) << t.dump();
    EXPECT_EQ(t["turn_ons"], 2);
  }
}

// Every power_cycles step is judged; a drifting ladder's asymmetry without a TC is stated, not
// judged, and said so.
TEST(AcceptanceVerdict, EveryTurnOnStepIsJudgedAndAnUnjudgedAsymmetryIsNamed) {
  auto serials = nlohmann::json::parse(R"([{"serial": "A", "ladders": [
      {"label": "drifting", "ok": true, "asymmetry_ppm": 45.0, "asymmetry_judged": false,
       "asymmetry_note": "the plateau drifted 3.1 C"}], "positions": [],
      "turn_on": {"ok": true, "repeatability_dph": 0.004, "max_warmup_s": 100},
      "turn_on_steps": [
        {"label": "room", "ok": true, "repeatability_dph": 0.004, "max_warmup_s": 100},
        {"label": "hot", "ok": true, "repeatability_dph": 0.02, "max_warmup_s": 900}]}])");
  station::PartLimits part;
  part.number = "GX";
  part.acceptance = station::AcceptanceLimits{};
  part.acceptance->max_asymmetry_ppm = 30;
  part.acceptance->max_turn_on_repeatability_dph = 0.01;
  part.acceptance->max_warmup_s = 600;
  station::judge_acceptance(serials, {{"A", part}});
  const auto& v = serials[0]["verdict"];
  EXPECT_FALSE(v["pass"].get<bool>());
  EXPECT_EQ(v["checked"].get<int>(), 4);  // two steps x two limits; the asymmetry not judged
  EXPECT_EQ(v["failed"], (nlohmann::json{"turn-on repeatability at 'hot' 0.02 deg/h above 0.01",
                                         "warm-up at 'hot' 900 s above 600"}));
  EXPECT_EQ(v["not_judged"],
            (nlohmann::json{"asymmetry at 'drifting': the plateau drifted 3.1 C"}));
  EXPECT_NE(station::acceptance_verdict_text(v).find("not judged: asymmetry at 'drifting'"),
            std::string::npos);
}
