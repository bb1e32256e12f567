// Issue 36, the hostile review's holes in the acceptance protocol's checks: repeated ladder rates
// and position angles refused at parse (file:line and both entries named), and a ladder beyond
// the turntable's rate or acceleration limit refused once, before the run exists, for every way a
// run starts (check_acceptance_rig from Sequencer::create_run: run --config, serve, run --sim).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "station/common/input_error.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/acceptance_runner.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

std::string parse_error(const std::string& step_body) {
  try {
    station::parse_protocol(
        "name = \"p\"\n[[step]]\n" + step_body + "[[step]]\ntype = \"lock_turntable\"\n", "p.toml");
  } catch (const station::InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kLadder = "type = \"rate_ladder\"\n";
const std::string kPositions = "type = \"positions\"\n";

// The rig's check of a protocol; "" when it passes.
std::string rig_error(const std::string& step_body, const std::string& turntable_toml) {
  const auto p = station::parse_protocol(
      "name = \"p\"\n[[step]]\n" + step_body + "[[step]]\ntype = \"lock_turntable\"\n", "p.toml");
  const auto c = station::parse_station_config(
      "[station]\nlatitude_deg = 39.9\n[chamber]\nendpoint = \"tcp://127.0.0.1:1502\"\n"
      "[turntable]\n" +
          turntable_toml +
          "[can]\ntransport = \"unix:/tmp/x.can\"\n[[slot]]\nnode = 1\nserial = \"A\"\n",
      "rig.toml");
  try {
    station::check_acceptance_rig(p, c, true);
  } catch (const station::InputError& e) {
    return e.what();
  }
  return "";
}

struct Outcome {
  int status = -1;
  std::string out;
};

Outcome run_station(const std::string& args) {
  const std::string cmd =
      std::string(STATION_BINARY_DIR) + "/station/station " + args + " 2>/dev/null";
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

}  // namespace

// A rate given twice is one point measured twice: the line would count it double. Rates closer
// than the step's rate_tolerance_dps are one rate (the read-back cannot tell them apart).
TEST(AcceptanceChecks, ARepeatedLadderRateIsRefusedNamingBothEntries) {
  EXPECT_NE(parse_error(kLadder + "rates_dps = [10, 100, 10]\n")
                .find("p.toml:4: key 'step[0].rates_dps': entries 0 and 2: 10 and 10 are one rate"),
            std::string::npos)
      << parse_error(kLadder + "rates_dps = [10, 100, 10]\n");
  EXPECT_NE(parse_error(kLadder + "rates_dps = [1, 1.01, 5]\n").find("entries 0 and 1"),
            std::string::npos);
  // Tighter tolerance: the same two rates are two points.
  EXPECT_EQ(parse_error(kLadder + "rates_dps = [1, 1.01, 5]\nrate_tolerance_dps = 0.001\n"), "");
  // Just outside the default 0.05 deg/s: accepted.
  EXPECT_EQ(parse_error(kLadder + "rates_dps = [1, 1.06]\n"), "");
}

// Angles are the same angle mod 360 within the runner's in-position tolerance (0.1 deg).
TEST(AcceptanceChecks, AnglesOneApartByLessThanTheToleranceMod360AreRefused) {
  const std::string e = parse_error(kPositions + "angles_deg = [0, 90, 360]\n");
  EXPECT_NE(e.find("p.toml:4: key 'step[0].angles_deg': entries 0 and 2: 0 and 360 are one angle "
                   "(mod 360 deg, closer than the table's 0.1 deg in-position tolerance)"),
            std::string::npos)
      << e;
  EXPECT_NE(parse_error(kPositions + "angles_deg = [-90, 180, 270.05]\n").find("entries 0 and 2"),
            std::string::npos);
  EXPECT_NE(parse_error(kPositions + "angles_deg = [0, 359.95, 120]\n").find("entries 0 and 1"),
            std::string::npos);
  EXPECT_EQ(parse_error(kPositions + "angles_deg = [0, 90, 180.2, 270]\n"), "");
  EXPECT_EQ(parse_error(kPositions + "angles_deg = [0, 0.2, 180]\n"), "");
}

// The station's own table map refuses a demand beyond 500 deg/s: a ladder asking more is refused
// before the run, naming the step, the rate and the limit; a configured lower rating wins; an
// acceleration beyond the configured one is refused too (the schedule would measure too soon).
TEST(AcceptanceChecks, ALadderBeyondTheTablesLimitsIsRefusedBeforeTheRun) {
  const std::string generic = "endpoint = \"tcp://127.0.0.1:1503\"\n";
  const std::string ladder = kLadder + "rates_dps = [10, 600]\n";
  EXPECT_NE(rig_error(ladder, generic)
                .find("p.toml:2: step[0] rate_ladder: rates_dps entry 1: 600 deg/s is beyond the "
                      "turntable's rate limit 500 deg/s (its dialect's own limit, model "
                      "generic_plc)"),
            std::string::npos)
      << rig_error(ladder, generic);
  EXPECT_EQ(rig_error(kLadder + "rates_dps = [10, 500]\n", generic), "");
  EXPECT_NE(rig_error(kLadder + "rates_dps = [10, 300]\n", generic + "max_rate_dps = 200\n")
                .find("300 deg/s is beyond the turntable's rate limit 200 deg/s ([turntable] "
                      "max_rate_dps"),
            std::string::npos);
  EXPECT_NE(rig_error(kLadder + "rates_dps = [10, 20]\naccel_dps2 = 20\n",
                      generic + "max_accel_dps2 = 10\n")
                .find("p.toml:2: step[0] rate_ladder: accel_dps2 20 deg/s^2 is beyond the "
                      "turntable's acceleration limit 10 deg/s^2"),
            std::string::npos);
  EXPECT_EQ(rig_error(kLadder + "rates_dps = [10, 20]\naccel_dps2 = 10\n",
                      generic + "max_accel_dps2 = 10\n"),
            "");
  // An ACUTROL's limit is the unit's own (read at connect): unknown here unless configured.
  const std::string acutrol = "model = \"acutrol3000\"\nendpoint = \"tcp://127.0.0.1:9878\"\n";
  EXPECT_EQ(rig_error(ladder, acutrol), "");
  EXPECT_NE(rig_error(ladder, acutrol + "max_rate_dps = 400\n").find("limit 400 deg/s"),
            std::string::npos);
}

TEST(AcceptanceChecks, TableLimitsAreTurntableKeysWithinRange) {
  const auto error = [](const std::string& toml) {
    try {
      station::parse_station_config("[station]\nlatitude_deg = 39.9\n" + toml +
                                        "[can]\ntransport = \"unix:/tmp/x.can\"\n[[slot]]\n"
                                        "node = 1\nserial = \"A\"\n",
                                    "rig.toml");
    } catch (const station::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("[chamber]\nendpoint = \"tcp://127.0.0.1:1502\"\nmax_rate_dps = 5\n")
                .find("key 'chamber.max_rate_dps': is a [turntable] key"),
            std::string::npos);
  EXPECT_NE(error("[chamber]\nendpoint = \"tcp://127.0.0.1:1502\"\n[turntable]\nendpoint = "
                  "\"tcp://127.0.0.1:1503\"\nmax_accel_dps2 = -1\n")
                .find("turntable.max_accel_dps2"),
            std::string::npos);
}

// The same refusal through run --sim (its table: 1000 deg/s, 10 deg/s^2, printed in the
// configuration it stores): exit 2's InputError before the run exists, nothing stored.
TEST(AcceptanceChecks, RunSimRefusesALadderFasterThanItsTableAccelerates) {
  const std::string db = station::testing_support::fresh_db("ladder_accel");
  const std::string path = db + ".toml";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(
        "name = \"fast\"\n[[step]]\ntype = \"rate_ladder\"\nrates_dps = [10, 20]\n"
        "accel_dps2 = 50\n[[step]]\ntype = \"lock_turntable\"\n",
        f);
    std::fclose(f);
  }
  station::SimRunOptions o;
  o.db_path = db;
  o.protocol = path;
  o.progress = false;
  o.fresh = true;
  o.gyros = 1;
  try {
    station::run_simulated(o);
    ADD_FAILURE() << "a ladder at 50 deg/s^2 ran on a 10 deg/s^2 table";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":2: step[0] rate_ladder: accel_dps2 50 deg/s^2 "
                                                "is beyond the turntable's acceleration limit 10"),
              std::string::npos)
        << e.what();
  }
  station::Store store(db, station::OpenMode::read_only);
  auto runs = store.db().prepare("SELECT count(*) FROM runs");
  ASSERT_TRUE(runs.step());
  EXPECT_EQ(runs.column_int(0), 0);
}

// `fit --acceptance` on a run of acceptance steps only (no record window, no thermal bins): each
// serial's thermal fit is skipped (exit 1, as `fit --help` documents) and its acceptance figures
// are computed, stored and printed, as text and as JSON, for --all and for --serial.
TEST(AcceptanceChecks, FitAcceptanceOnARunWithoutBinsPrintsTheFigures) {
  station::SimRunOptions o;
  o.db_path = station::testing_support::fresh_db("fit_acceptance_only");
  o.protocol = std::string(STATION_TEST_DATA_DIR) + "/acceptance_short.toml";
  o.progress = false;
  o.fresh = true;
  o.gyros = 2;
  o.parts_path = std::string(STATION_SOURCE_DIR) + "/station/parts/example_parts.toml";
  o.part_number = "GX-200";
  const auto report = station::run_simulated(o);
  const std::int64_t run = report["run_id"];
  const std::string serial = report["gyros"][0]["serial"];
  const auto text = run_station("fit --db " + o.db_path + " --all --run " + std::to_string(run) +
                                " --acceptance");
  EXPECT_EQ(text.status, 1) << text.out;
  EXPECT_NE(text.out.find("run " + std::to_string(run) + ": no thermal fit for these serials"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find(serial + "\n  scale factor"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("  acceptance verdict (GX-200): "), std::string::npos) << text.out;
  const auto js = run_station("fit --db " + o.db_path + " --all --run " + std::to_string(run) +
                              " --acceptance --json");
  EXPECT_EQ(js.status, 1);
  const auto arr = nlohmann::json::parse(js.out);
  ASSERT_EQ(arr.size(), 2u) << js.out;
  EXPECT_TRUE(arr[0]["fit_id"].is_null());
  EXPECT_EQ(arr[0]["acceptance_run_id"], run);
  EXPECT_TRUE(arr[0]["acceptance_figures"]["ladders"][0]["ok"].get<bool>()) << js.out;
  const auto one = run_station("fit --db " + o.db_path + " --serial " + serial + " --acceptance");
  EXPECT_EQ(one.status, 1) << one.out;
  EXPECT_NE(one.out.find("no thermal fit for this serial"), std::string::npos) << one.out;
  EXPECT_EQ(one.out.find(report["gyros"][1]["serial"].get<std::string>()), std::string::npos)
      << one.out;  // only the serial asked for
  // An unknown serial or run stays an error (exit 2), --acceptance or not.
  EXPECT_EQ(run_station("fit --db " + o.db_path + " --serial NOPE --acceptance").status, 2);
  EXPECT_EQ(run_station("fit --db " + o.db_path + " --serial " + serial + " --runs 99 --acceptance")
                .status,
            2);
  // Without --acceptance, --serial is refused as before (nothing to fit: exit 2).
  EXPECT_EQ(run_station("fit --db " + o.db_path + " --serial " + serial).status, 2);
}

// run --sim --fault in the final lock's last seconds: the lock waits for the table (nominally
// 0 s, it takes the table's travel), so the up-front check counts it as a wait and a fault there
// lands (before: refused as "past the end of protocol" at 62.4 s, the ladder's nominal end, though
// the run went on to t = 75 s locking the table at 180 deg).
TEST(AcceptanceChecks, AFaultInTheFinalLocksLastSecondsLands) {
  const std::string db = station::testing_support::fresh_db("fault_in_lock");
  const std::string path = db + ".toml";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(
        "name = \"lockend\"\n[[step]]\ntype = \"rate_ladder\"\nrates_dps = [10, 20]\n"
        "settle_s = 2\ndwell_s = 10\n[[step]]\ntype = \"lock_turntable\"\n"
        "position_deg = 180\n",
        f);
    std::fclose(f);
  }
  station::SimRunOptions o;
  o.db_path = db;
  o.protocol = path;
  o.progress = false;
  o.fresh = true;
  o.gyros = 1;
  o.faults = {{64.0, "door open"}, {65.0, "door close"}};
  const auto r = station::run_simulated(o);
  EXPECT_EQ(r["state"], "completed") << r.dump();
  station::Store store(db, station::OpenMode::read_only);
  const auto count = [&](const std::string& sql) {
    auto st = store.db().prepare(sql);
    EXPECT_TRUE(st.step()) << sql;
    return st.column_double(0);
  };
  EXPECT_EQ(count("SELECT count(*) FROM events WHERE kind = 'safe_hold' AND t_s = 64"), 1);
  EXPECT_EQ(count("SELECT count(*) FROM events WHERE kind = 'safe_hold_cleared' AND t_s = 65"), 1);
  EXPECT_GT(count("SELECT max(t_s) FROM samples"), 65);
}
