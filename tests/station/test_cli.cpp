// The `station` executable end to end: analyze/adev output and exit status 2 on bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "drivers/can/candump_log.hpp"

namespace {

struct Outcome {
  int status = -1;
  std::string out;
};

// Runs the station binary with `args` (stderr folded into the output).
Outcome run_station(const std::string& args, bool with_stderr = true) {
  const std::string cmd = std::string(STATION_BINARY_DIR) + "/station/station " + args +
                          (with_stderr ? " 2>&1" : " 2>/dev/null");
  Outcome o;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return o;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) o.out.append(buf.data(), n);
  const int raw = pclose(p);
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return o;
}

const std::string kExample = std::string(STATION_SOURCE_DIR) + "/examples/thermal_cycle.csv";

}  // namespace

TEST(Cli, AnalyzeExampleRecoversTheGeneratorsCoefficients) {
  // examples/thermal_cycle.csv was made by scripts/make_example_csv.py with B0 0.05 deg/h,
  // k1 1.2e-3 deg/h/C, k0 0.012 deg/h/C and Earth rate at 39.9 N removed by the command.
  const auto o =
      run_station("analyze " + kExample + " --temp2-col temp2_c --latitude 39.9 --axis up --json");
  ASSERT_EQ(o.status, 0) << o.out;
  const auto j = nlohmann::json::parse(o.out);
  const auto& c = j["coefficients"];
  const auto& se = j["std_errors"];
  EXPECT_NEAR(c["k1"].get<double>(), 1.2e-3, 4 * se["k1"].get<double>());
  EXPECT_NEAR(c["k0"].get<double>(), 0.012, 4 * se["k0"].get<double>());
  EXPECT_NEAR(c["B0"].get<double>(), 0.05, 4 * se["B0"].get<double>());
  EXPECT_EQ(j["bins"].get<int>(), 66);
  EXPECT_LT(j["std_ratio"].get<double>(), 0.2);
  EXPECT_NEAR(j["improvement_pct"].get<double>(), 100 * (1 - j["std_ratio"].get<double>()), 1e-9);
  EXPECT_TRUE(j["warnings"].empty());
}

TEST(Cli, AnalyzeBadInputExitsTwoNamingFileLineColumn) {
  const std::string path = testing::TempDir() + "bad_cli.csv";
  std::ofstream(path) << "time_s,rate_dph,temp_c\n0,1,2\n1,x,2\n";
  const auto o = run_station("analyze " + path + " --terms dT --earth-rate-dph 0");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.out.find("bad_cli.csv:3: column 'rate_dph': not a number: 'x'"), std::string::npos)
      << o.out;
}

TEST(Cli, AnalyzeTooFewBinsForTheTermsExitsTwo) {
  const std::string path = testing::TempDir() + "short_cli.csv";
  std::ofstream f(path);
  f << "time_s,rate_dph,temp_c\n";
  for (int i = 0; i < 1800; ++i) f << i << ",1," << i * 0.01 << "\n";
  f.close();
  const auto o = run_station("analyze " + path + " --terms dT,dT2,dT3 --earth-rate-dph 0");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.out.find("too few bins: 3 bins for 4 coefficients"), std::string::npos) << o.out;
}

TEST(Cli, AnalyzeNeedsAGradientSourceForGradT) {
  const std::string path = testing::TempDir() + "no_grad_cli.csv";
  std::ofstream f(path);
  f << "time_s,rate_dph,temp_c\n";
  for (int i = 0; i < 7200; ++i) f << i << ",1," << i * 0.01 << "\n";
  f.close();
  const auto o = run_station("analyze " + path + " --earth-rate-dph 0");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.out.find("no grad_c or temp2_c column"), std::string::npos) << o.out;
}

// Issue 23: the shipped example as the README shows it. Its temp2_c column is picked up without
// --temp2-col; without a latitude it is refused rather than fitting Earth rate into B0.
TEST(Cli, AnalyzeTakesTheDocumentedColumnsAndNeedsTheLatitude) {
  const auto o = run_station("analyze " + kExample + " --latitude 39.9");
  ASSERT_EQ(o.status, 0) << o.out;
  EXPECT_NE(o.out.find("k0"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("deg/h/C (gradient)"), std::string::npos) << "unit column\n" << o.out;
  const auto explicit_col = run_station("analyze " + kExample + " --latitude 39.9 --json");
  const auto named =
      run_station("analyze " + kExample + " --temp2-col temp2_c --latitude 39.9 --json");
  ASSERT_EQ(explicit_col.status, 0);
  const auto j = nlohmann::json::parse(explicit_col.out);
  EXPECT_EQ(j["coefficients"], nlohmann::json::parse(named.out)["coefficients"]);
  // Every JSON object with coefficients names their units.
  EXPECT_EQ(j["units"]["B0"], "deg/h");
  EXPECT_EQ(j["units"]["k1"], "deg/h/C");
  EXPECT_EQ(j["units"]["k0"], "deg/h/C (gradient)");
  const auto no_lat = run_station("analyze " + kExample);
  EXPECT_EQ(no_lat.status, 2);
  EXPECT_NE(no_lat.out.find("--latitude"), std::string::npos) << no_lat.out;
}

// Issue 23: an unknown subcommand is named, with the known ones.
TEST(Cli, AnUnknownSubcommandIsNamedWithTheKnownOnes) {
  const auto o = run_station("bogus");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.out.find("unknown subcommand 'bogus'"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("analyze"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("release"), std::string::npos) << o.out;
}

TEST(Cli, AdevJsonHasRowsAndNoise) {
  const auto o = run_station("adev " + kExample + " --col rate_dph --json");
  ASSERT_EQ(o.status, 0) << o.out;
  const auto j = nlohmann::json::parse(o.out);
  ASSERT_GT(j["rows"].size(), 10u);
  EXPECT_EQ(j["rows"][0]["m"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(j["rows"][1]["tau_s"].get<double>(), 2.0);
  // At m = 1 the overlapping sum has samples - 1 terms.
  const std::size_t rows_in_example = j["rows"][0]["n"].get<std::size_t>() + 1;
  std::set<std::string> methods;
  for (const auto& r : j["rows"]) {
    EXPECT_LE(r["ci_low"].get<double>(), r["adev"].get<double>());
    EXPECT_GE(r["ci_high"].get<double>(), r["adev"].get<double>());
    // How alpha was found: lag-1 (30 averages or more), B1 (8 to 29), none (carried).
    const auto method = r["noise_id"].get<std::string>();
    methods.insert(method);
    const std::size_t averages = rows_in_example / r["m"].get<std::size_t>();
    const std::string want = averages >= 30 ? "lag1" : averages >= 8 ? "b1" : "none";
    EXPECT_EQ(method, want) << "m " << r["m"];
    EXPECT_EQ(r["alpha_identified"].get<bool>(), method != "none");
  }
  EXPECT_EQ(methods, (std::set<std::string>{"lag1", "b1", "none"}));
  EXPECT_TRUE(j["noise"].contains("angle_random_walk_deg_rth"));
}

TEST(Cli, AdevRejectsATauThatIsNotAMultipleOfThePeriod) {
  const auto o = run_station("adev " + kExample + " --col rate_dph --rate-hz 1 --taus 1,2.5");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.out.find("2.5 s is not a whole multiple"), std::string::npos) << o.out;
}

TEST(Cli, AdevMissingColumnExitsTwo) {
  const auto o = run_station("adev " + kExample + " --col nope");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.out.find("no column 'nope'"), std::string::npos) << o.out;
}

TEST(Cli, SimRunThenFitAllAndExport) {
  const std::string db = testing::TempDir() + "cli_sim-" + std::to_string(getpid()) + ".db";
  for (const char* ext : {"", "-wal", "-shm"}) std::remove((db + ext).c_str());
  const auto run = run_station("run --sim --gyros 2 --seed 9 --new --json --db " + db +
                                   " --protocol " + STATION_TEST_DATA_DIR "/short_cycle.toml",
                               false);
  ASSERT_EQ(run.status, 0) << run.out;
  const auto j = nlohmann::json::parse(run.out);  // exactly one JSON object on stdout
  for (const char* key : {"run_id", "sim_s", "wall_s", "gyros"})
    EXPECT_TRUE(j.contains(key)) << key;
  ASSERT_EQ(j["gyros"].size(), 2u);
  for (const char* key :
       {"serial", "true", "fitted", "std_errors", "std_before_dph", "std_after_dph", "std_ratio"}) {
    EXPECT_TRUE(j["gyros"][0].contains(key)) << key;
  }
  const auto run_id = std::to_string(j["run_id"].get<int>());

  const auto fit =
      run_station("fit --db " + db + " --all --run " + run_id + " --terms dT --json", false);
  ASSERT_EQ(fit.status, 0) << fit.out;
  const auto f = nlohmann::json::parse(fit.out);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_FALSE(f[0]["coefficients"].contains("k0"));  // --terms dT: B0 and k1 only
  EXPECT_TRUE(f[0]["coefficients"].contains("k1"));

  const auto one = run_station("fit --db " + db + " --serial SIM-0002 --json", false);
  ASSERT_EQ(one.status, 0) << one.out;
  EXPECT_EQ(nlohmann::json::parse(one.out)["runs"][0].get<int>(), j["run_id"].get<int>());

  // Nothing released yet: export refuses (issue 21), --fit exports the named fit with a warning.
  const auto unreleased = run_station("export --db " + db + " --serial SIM-0002");
  EXPECT_EQ(unreleased.status, 2);
  EXPECT_NE(unreleased.out.find("serial 'SIM-0002' has no released calibration"), std::string::npos)
      << unreleased.out;
  const auto latest = nlohmann::json::parse(one.out)["fit_id"].get<std::int64_t>();
  const auto named = run_station("export --db " + db + " --fit " + std::to_string(latest));
  EXPECT_EQ(named.status, 0) << named.out;
  EXPECT_NE(named.out.find("is NOT the released calibration"), std::string::npos) << named.out;
  const auto rel = run_station(
      "release --db " + db + " --fit " + std::to_string(latest) + " --by tester", false);
  ASSERT_EQ(rel.status, 0) << rel.out;
  const auto csv = run_station("export --db " + db + " --serial SIM-0002 --format csv", false);
  ASSERT_EQ(csv.status, 0) << csv.out;
  EXPECT_EQ(csv.out.rfind("serial,part_number,fit_id,term,value,std_error,unit,t_ref_c,t_min_c,"
                          "t_max_c,grad_min_c,grad_max_c,outside_span,bin_s,runs,verdict,"
                          "failed_limits,released,released_utc,released_by,note,override,"
                          "software_version,crc32,scale_factor,",
                          0),
            0u)
      << csv.out;
  EXPECT_NE(csv.out.find("SIM-0002,"), std::string::npos);
  EXPECT_NE(csv.out.find(",k0,"), std::string::npos);  // the released fit is the dT+gradT one
  EXPECT_NE(csv.out.find(",yes,"), std::string::npos);
  EXPECT_NE(csv.out.find(",tester,"), std::string::npos);

  const auto missing = run_station("export --db " + db + " --serial NOPE");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.out.find("serial 'NOPE' has no released calibration"), std::string::npos)
      << missing.out;
}

TEST(Cli, SimRunRecordsEveryCanFrameInCandumpFormat) {
  const std::string db = testing::TempDir() + "cli_rec-" + std::to_string(getpid()) + ".db";
  const std::string log = testing::TempDir() + "cli_rec-" + std::to_string(getpid()) + ".log";
  for (const char* ext : {"", "-wal", "-shm"}) std::remove((db + ext).c_str());
  std::remove(log.c_str());
  const auto run = run_station("run --sim --gyros 2 --new --json --db " + db + " --record-can " +
                                   log + " --protocol " + STATION_TEST_DATA_DIR "/short_cycle.toml",
                               false);
  ASSERT_EQ(run.status, 0) << run.out;
  const auto ticks = nlohmann::json::parse(run.out)["sim_s"].get<double>() + 1;  // t = 0 .. sim_s
  const auto records = station::drivers::can::read_candump_log(log);
  int syncs = 0, counts_node1 = 0, counts_node2 = 0;
  for (const auto& r : records) {
    if (r.frame.can_id == 0x080) ++syncs;
    if (r.frame.can_id == 0x281) ++counts_node1;
    if (r.frame.can_id == 0x282) ++counts_node2;
  }
  EXPECT_EQ(syncs, static_cast<int>(ticks));  // one SYNC per tick
  EXPECT_EQ(counts_node1, syncs);             // every latch answered
  EXPECT_EQ(counts_node2, syncs);
}

// gpsd-style regression: a recorded session replayed through the same driver gives the stored
// fit exactly; a log missing one COUNTS frame inside the record window does not.
TEST(Cli, ReplayOfARecordedRunReproducesItsFitAndCatchesATamperedLog) {
  const std::string db = testing::TempDir() + "cli_replay-" + std::to_string(getpid()) + ".db";
  const std::string log = testing::TempDir() + "cli_replay-" + std::to_string(getpid()) + ".log";
  for (const char* ext : {"", "-wal", "-shm"}) std::remove((db + ext).c_str());
  std::remove(log.c_str());
  ASSERT_EQ(run_station("run --sim --gyros 2 --new --db " + db + " --record-can " + log +
                        " --protocol " + STATION_TEST_DATA_DIR "/short_cycle.toml")
                .status,
            0);
  const auto same = run_station("replay " + log + " --db " + db + " --run 1 --json", false);
  ASSERT_EQ(same.status, 0) << same.out;
  const auto j = nlohmann::json::parse(same.out);
  EXPECT_TRUE(j["identical"].get<bool>());
  EXPECT_EQ(j["gyros"].size(), 2u);

  // Drop the first COUNTS frame of node 1 past 80 % of the log (inside the record window).
  std::ifstream in(log);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  in.close();
  std::size_t drop = lines.size() * 8 / 10;
  while (drop < lines.size() && lines[drop].find(" 281#") == std::string::npos) ++drop;
  ASSERT_LT(drop, lines.size());
  lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(drop));
  std::ofstream out(log);
  for (const auto& l : lines) out << l << '\n';
  out.close();
  const auto tampered = run_station("replay " + log + " --db " + db + " --run 1 --json", false);
  EXPECT_EQ(tampered.status, 1) << tampered.out;
  EXPECT_FALSE(nlohmann::json::parse(tampered.out)["identical"].get<bool>());
}
