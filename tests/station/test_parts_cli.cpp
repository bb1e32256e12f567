// Part numbers and verdicts through the `station` binary: a bad part file is one line and exit 2
// before anything moves; a simulated run, `fit`, `export` and `history` carry the verdict.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace ts = station::testing_support;

struct Outcome {
  int status = -1;
  std::string out;
};

// Runs the station binary; stdout only, or stdout and stderr together.
Outcome station_cmd(const std::string& args, bool with_stderr = true) {
  const std::string out = ::testing::TempDir() + "parts-cli-" + std::to_string(getpid()) + ".out";
  const std::string redirect = with_stderr ? " >" + out + " 2>&1" : " >" + out + " 2>/dev/null";
  const int rc = std::system((ts::kStationBin + " " + args + redirect).c_str());
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, ts::slurp(out)};
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

int lines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

const std::string kShortCycle = STATION_TEST_DATA_DIR "/short_cycle.toml";

// Every limit loose except the bins: short_cycle records 2 h, 12 bins of 600 s, not 1000.
const std::string kParts = R"([part."LOOSE"]
B0_dph = { min = -10.0, max = 10.0 }
k1_dph_per_c = { min = -1.0, max = 1.0 }
max_std_ratio = 10.0
[part."LONG"]
min_complete_bins = 1000
)";

}  // namespace

TEST(PartsCli, ABadPartFileIsOneLineAndExit2BeforeTheDatabaseIsTouched) {
  const auto bad =
      write_temp("cli_bad_parts.toml", "[part.A]\nk1_dph_per_c = { min = 1, max = 0 }\n");
  const std::vector<std::pair<std::string, std::string>> cases{
      {"--parts " + bad, bad + ":2: key 'part.A.k1_dph_per_c.min': min 1 is above max 0"},
      {"--parts /nonexistent/p.toml", "/nonexistent/p.toml: cannot open the part file"},
      {"--parts " + write_temp("cli_parts.toml", kParts) + " --part NOPE",
       "--part NOPE: " + ::testing::TempDir() + "cli_parts.toml has no such part"},
      {"--part LOOSE", "--part: give the part file with --parts FILE"},
  };
  for (const auto& [args, message] : cases) {
    const auto db = ts::fresh_db("cli-bad-parts");
    const auto o = station_cmd("run --sim --gyros 1 --new --db " + db + " " + args);
    EXPECT_EQ(o.status, 2) << args << "\n" << o.out;
    EXPECT_EQ(o.out, "station: " + message + "\n") << args;
    EXPECT_NE(access(db.c_str(), F_OK), 0) << args << ": created " << db;
    EXPECT_NE(access((db + ".lock").c_str(), F_OK), 0) << args << ": locked " << db;
  }
}

TEST(PartsCli, ARigSlotNamingAnUnknownPartStopsBeforeAnyDeviceIsTouched) {
  // The devices of examples/station.toml are not running: the part check comes first.
  const auto parts = write_temp("rig_parts.toml", kParts);
  std::ifstream in(std::string(STATION_SOURCE_DIR) + "/examples/station.toml");
  std::string config((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  config.insert(config.find("axis = \"up\""), "part = \"GX-9\"\n");
  const auto path = write_temp("rig_unknown_part.toml", config);
  const auto db = ts::fresh_db("cli-rig-part");
  const auto o = station_cmd("run --config " + path + " --db " + db + " --parts " + parts);
  EXPECT_EQ(o.status, 2) << o.out;
  EXPECT_EQ(lines(o.out), 1) << o.out;
  EXPECT_NE(o.out.find(path + ":"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("key 'slot[0].part': part 'GX-9' is not in " + parts +
                       " (it has: LONG, "
                       "LOOSE)"),
            std::string::npos)
      << o.out;
  EXPECT_NE(access(db.c_str(), F_OK), 0);
}

TEST(PartsCli, SimRunFitExportAndHistoryCarryTheVerdict) {
  const auto parts = write_temp("sim_parts.toml", kParts);
  const auto db = ts::fresh_db("cli-sim-parts");
  const auto run = station_cmd("run --sim --gyros 2 --seed 3 --new --json --db " + db +
                                   " --protocol " + kShortCycle + " --parts " + parts,
                               false);
  ASSERT_EQ(run.status, 0) << run.out;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["gyros"].size(), 2u);
  for (const auto& g : j["gyros"]) {
    // The first part in sort order is LONG: only its bins limit, which 12 bins fail.
    EXPECT_EQ(g["part_number"], "LONG");
    const auto& v = g["verdict"];
    EXPECT_EQ(v["pass"], false);
    ASSERT_EQ(v["failed"].size(), 1u) << v.dump();
    EXPECT_EQ(v["failed"][0]["limit"], "min_complete_bins");
    EXPECT_EQ(v["failed"][0]["value"].get<double>(), g["bins"].get<double>());
    EXPECT_EQ(v["failed"][0]["bound"], 1000.0);
  }

  // A refit judges against the limits stored with the run; --parts/--part against a file.
  const auto stored = station_cmd("fit --db " + db + " --serial SIM-0001 --json", false);
  ASSERT_EQ(stored.status, 0) << stored.out;
  EXPECT_EQ(nlohmann::json::parse(stored.out)["verdict"]["failed"][0]["limit"],
            "min_complete_bins");
  const auto loose = station_cmd(
      "fit --db " + db + " --serial SIM-0001 --json --parts " + parts + " --part LOOSE", false);
  ASSERT_EQ(loose.status, 0) << loose.out;
  const auto lj = nlohmann::json::parse(loose.out);
  EXPECT_EQ(lj["verdict"]["pass"], true) << lj.dump();
  EXPECT_EQ(lj["verdict"]["checked"], 5);
  EXPECT_EQ(lj["part_number"], "LOOSE");

  const auto text = station_cmd("fit --db " + db + " --serial SIM-0002 --terms dT", false);
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_NE(text.out.find("verdict: FAIL (part LONG): min_complete_bins 12 < 1000 (by 988)"),
            std::string::npos)
      << text.out;

  // The passing fit released and exported; the failing one refused without an override.
  const auto pass_fit = std::to_string(lj["fit_id"].get<std::int64_t>());
  ASSERT_EQ(station_cmd("release --db " + db + " --fit " + pass_fit + " --by qa", false).status, 0);
  const auto csv = station_cmd("export --db " + db + " --serial SIM-0001 --format csv", false);
  ASSERT_EQ(csv.status, 0) << csv.out;
  EXPECT_NE(csv.out.find(",pass,,yes,"), std::string::npos) << csv.out;
  EXPECT_NE(csv.out.find("SIM-0001,LOOSE,"), std::string::npos) << csv.out;
  const auto failing =
      nlohmann::json::parse(station_cmd("fit --db " + db + " --serial SIM-0002 --json", false).out);
  const auto fail_fit = std::to_string(failing["fit_id"].get<std::int64_t>());
  const auto refused = station_cmd("release --db " + db + " --fit " + fail_fit + " --by qa");
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.out.find("its verdict failed"), std::string::npos) << refused.out;
  EXPECT_NE(refused.out.find("--override"), std::string::npos) << refused.out;
  const auto ej =
      nlohmann::json::parse(station_cmd("export --db " + db + " --fit " + fail_fit, false).out);
  EXPECT_EQ(ej["verdict"]["failed"][0]["limit"], "min_complete_bins");
  EXPECT_TRUE(ej["release"].is_null());

  const auto hist = station_cmd("history --db " + db + " --serial SIM-0001 --json", false);
  ASSERT_EQ(hist.status, 0) << hist.out;
  const auto h = nlohmann::json::parse(hist.out);
  EXPECT_EQ(h["runs"].size(), 1u);
  EXPECT_EQ(h["runs"][0]["part_number"], "LONG");
  EXPECT_EQ(h["fits"].size(), 3u);          // the run's fit and two refits of the same run
  EXPECT_EQ(h["calibrations"].size(), 1u);  // ... are one calibration
  EXPECT_TRUE(h["drift"].empty());
  const auto missing = station_cmd("history --db " + db + " --serial NOPE");
  EXPECT_EQ(missing.status, 2) << missing.out;
  EXPECT_EQ(lines(missing.out), 1) << missing.out;
}

TEST(PartsCli, AFitWithoutAPartSaysSo) {
  const auto db = ts::fresh_db("cli-no-parts");
  const auto run = station_cmd(
      "run --sim --gyros 1 --new --json --db " + db + " --protocol " + kShortCycle, false);
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_TRUE(nlohmann::json::parse(run.out)["gyros"][0]["verdict"].is_null());
  const auto fit = station_cmd("fit --db " + db + " --serial SIM-0001", false);
  EXPECT_NE(fit.out.find("verdict: no part limits"), std::string::npos) << fit.out;
  const auto all = station_cmd("fit --db " + db + " --all --json", false);
  ASSERT_EQ(all.status, 0) << all.out;
  EXPECT_TRUE(nlohmann::json::parse(all.out)[0]["verdict"].is_null());
}

// Issue 32: a part that fixes the model and gives its noise. The run's fit and a refit use the
// part's model and weigh the part's noise; the fit records that the part chose the model; an
// explicit --terms overrides the model (exploratory) and records no choice; --select records
// the models it tried; without a part the fit says what it assumed about a walk.
TEST(PartsCli, ThePartsModelAndNoiseAreWhatTheFitUses) {
  const auto parts = write_temp("noise_parts.toml", R"([part."NOISY"]
max_std_ratio = 10.0
model = "dT,dT2,gradT"
[part."NOISY".noise]
arw_deg_rt_h = 0.003
rrw_dph_rt_h = 1e-4
trust_factor = 2
)");
  const auto db = ts::fresh_db("cli-part-noise");
  const auto run = station_cmd("run --sim --gyros 1 --seed 4 --new --json --db " + db +
                                   " --protocol " + kShortCycle + " --parts " + parts,
                               false);
  ASSERT_EQ(run.status, 0) << run.out;
  const auto fit =
      nlohmann::json::parse(station_cmd("fit --db " + db + " --serial SIM-0001 --json", false).out);
  EXPECT_TRUE(fit["coefficients"].contains("k2")) << fit.dump();
  EXPECT_EQ(fit["error_model"]["prior"]["rrw_dph_rt_h"], 1e-4) << fit["error_model"].dump();
  EXPECT_EQ(fit["model_choice"]["method"], "part file");
  EXPECT_EQ(fit["model_choice"]["chosen"], "B0+dT+dT2+gradT");
  EXPECT_NE(fit["walk"].get<std::string>().find("K 0.0001"), std::string::npos) << fit["walk"];
  EXPECT_EQ(fit["verdict"]["context"], fit["walk"]);

  const auto given = nlohmann::json::parse(
      station_cmd("fit --db " + db + " --serial SIM-0001 --terms dT --json", false).out);
  EXPECT_FALSE(given["coefficients"].contains("k0")) << given.dump();
  EXPECT_TRUE(given["model_choice"].is_null());

  const auto sel =
      station_cmd("fit --db " + db + " --serial SIM-0001 --select --terms dT,gradT", false);
  ASSERT_EQ(sel.status, 0) << sel.out;
  EXPECT_NE(sel.out.find("model selection (likelihood ratio):"), std::string::npos) << sel.out;
  EXPECT_NE(sel.out.find("B0+dT+gradT+dT3"), std::string::npos) << sel.out;
  EXPECT_EQ(sel.out.find("dTdt"), std::string::npos) << "a release could not carry it\n" << sel.out;
  const auto sj = nlohmann::json::parse(
      station_cmd("fit --db " + db + " --serial SIM-0001 --select --json", false).out);
  EXPECT_EQ(sj["model_choice"]["method"], "likelihood ratio") << sj["model_choice"].dump();
  EXPECT_GE(sj["model_choice"]["tried"].size(), 2u);

  // A part's model without k0 (or k1): the run's events and its table name what the fit has
  // (review: the event read past the coefficients, the table threw), and a verdict event keeps
  // to schemas/events.md.
  const auto dt_parts = write_temp("dt_parts.toml",
                                   "[part.\"DT\"]\nmax_std_ratio = 10.0\n"
                                   "model = \"dT\"\n");
  const auto dt_db = ts::fresh_db("cli-part-dt");
  const auto dt_run = station_cmd("run --sim --gyros 1 --new --db " + dt_db + " --protocol " +
                                  kShortCycle + " --parts " + dt_parts);
  EXPECT_EQ(dt_run.status, 0) << dt_run.out;
  EXPECT_EQ(dt_run.out.find("does not follow"), std::string::npos) << dt_run.out;
  EXPECT_EQ(dt_run.out.find("error"), std::string::npos) << dt_run.out;

  const auto bare_db = ts::fresh_db("cli-no-part-walk");
  ASSERT_EQ(
      station_cmd("run --sim --gyros 1 --new --db " + bare_db + " --protocol " + kShortCycle, false)
          .status,
      0);
  const auto bare = station_cmd("fit --db " + bare_db + " --serial SIM-0001", false);
  EXPECT_NE(bare.out.find("walk: the bins"), std::string::npos) << bare.out;
}
