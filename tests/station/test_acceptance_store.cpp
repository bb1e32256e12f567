// Issue 36's acceptance figures stored (migration 12): the table added to an older database, the
// rows a run's end writes equal to what run_acceptance and the verdict give, recomputed in place,
// `station history` with the scale factor's drift between two runs, and a run whose figures
// cannot be computed or stored still ending with its samples.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>

#include "schemas/migrations.hpp"
#include "station/acceptance/acceptance_history.hpp"
#include "station/acceptance/acceptance_record.hpp"
#include "station/parts/part_file.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/acceptance_results.hpp"
#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using nlohmann::json;

const std::string kParts = std::string(STATION_SOURCE_DIR) + "/station/parts/example_parts.toml";

// tests/data/acceptance_short.toml on two simulated GX-200 gyros: a ladder (4 points), four
// positions and two power cycles at room temperature, ~0.6 h simulated.
station::SimRunOptions short_acceptance(const std::string& db, std::uint64_t seed) {
  station::SimRunOptions o;
  o.db_path = db;
  o.protocol = std::string(STATION_TEST_DATA_DIR) + "/acceptance_short.toml";
  o.progress = false;
  o.fresh = true;
  o.gyros = 2;
  o.seed = seed;
  o.parts_path = kParts;
  o.part_number = "GX-200";
  return o;
}

// The part limits the run judged against, by serial (every simulated gyro is a GX-200).
std::map<std::string, station::PartLimits> gx200(station::Store& s, std::int64_t run_id) {
  const auto parts = station::load_part_file(kParts);
  std::map<std::string, station::PartLimits> out;
  for (const auto& slot : s.run_slots(run_id)) out[slot.serial] = parts.parts.at("GX-200");
  return out;
}

std::int64_t count(station::Store& s, const std::string& sql) {
  auto st = s.db().prepare(sql);
  EXPECT_TRUE(st.step());
  return st.column_int(0);
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

// A version-11 database (the one before the table): the next writer migrates it keeping its
// run, and rows go in and come back with their columns.
TEST(AcceptanceStore, MigrationTwelveAddsTheTableToAVersion11Database) {
  const auto path = station::testing_support::fresh_db("acceptance_v11");
  {
    station::Database db(path);
    for (std::size_t i = 0; i < 11; ++i) db.exec(station::schemas::kMigrations[i].second);
    db.exec("PRAGMA user_version = 11");
    db.exec(
        "INSERT INTO runs (id, started_utc, state, protocol_name, protocol_text, config_text, "
        "software_version, station) VALUES (1, 'x', 'completed', 'p', '', '', '0.1', 'rig');");
  }
  station::Store s(path);
  ASSERT_GE(s.db().schema_version(), 12);
  ASSERT_TRUE(s.find_run(1).has_value());
  const json a = json::parse(R"({"serial": "A", "ladders": [{"label": "room", "ok": true,
      "temp_c": 24.5, "sf_pulse_per_arcsec": 0.6667, "sf_se_pulse_per_arcsec": 2e-6,
      "nonlinearity_max_ppm_fs": 4.0, "asymmetry_ppm": -12.0, "asymmetry_se_ppm": 2.0}],
      "positions": [], "verdict": {"part": "GX", "pass": true, "checked": 3, "failed": []}})");
  station::replace_acceptance_rows(s, 1, {station::acceptance_row(1, a)});
  const auto rows = station::acceptance_rows_of_run(s, 1);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].figures, a);
  EXPECT_EQ(rows[0].sf_pulse_per_arcsec, 0.6667);  // the one ladder's K, at its temperature
  EXPECT_EQ(rows[0].sf_temp_c, 24.5);
  EXPECT_EQ(rows[0].asymmetry_se_ppm, 2.0);
  EXPECT_FALSE(rows[0].tc_ppm_per_c.has_value());  // one plateau: no temperature coefficient
  EXPECT_EQ(rows[0].part_number, "GX");
  EXPECT_EQ(rows[0].pass, true);
}

// The run's end stores, per serial, exactly what run_acceptance and the verdict give; its
// columns are the figures of that JSON; computing it again replaces the rows, never adds.
TEST(AcceptanceStore, TheRunsEndStoresWhatRunAcceptanceAndTheVerdictGive) {
  const auto o = short_acceptance(station::testing_support::fresh_db("acceptance_end"), 1);
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  const std::int64_t run = r["run_id"];
  station::Store s(o.db_path);
  const json expected = station::judged_acceptance(s, run, gx200(s, run));
  ASSERT_EQ(expected.size(), 2u);
  EXPECT_EQ(station::stored_acceptance_json(s, run), expected);
  const auto rows = station::acceptance_rows_of_run(s, run);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    SCOPED_TRACE(row.serial);
    const json& l = row.figures["ladders"][0];
    ASSERT_TRUE(l["ok"].get<bool>()) << l.dump();
    EXPECT_EQ(row.sf_pulse_per_arcsec, l["sf_pulse_per_arcsec"].get<double>());
    EXPECT_EQ(row.sf_se_pulse_per_arcsec, l["sf_se_pulse_per_arcsec"].get<double>());
    EXPECT_EQ(row.nonlinearity_max_ppm_fs, l["nonlinearity_max_ppm_fs"].get<double>());
    EXPECT_EQ(row.asymmetry_ppm, l["asymmetry_ppm"].get<double>());
    const json& p = row.figures["positions"][0];
    ASSERT_TRUE(p["ok"].get<bool>()) << p.dump();
    EXPECT_EQ(row.tilt_mrad, p["tilt_mrad"].get<double>());
    EXPECT_EQ(row.pass, row.figures["verdict"]["pass"].get<bool>());
    EXPECT_EQ(row.part_number, "GX-200");
  }
  // The end summary's figures (run --sim's, with the simulated truth beside) are these.
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_EQ(r["acceptance"][i]["ladders"][0]["sf_pulse_per_arcsec"],
              expected[i]["ladders"][0]["sf_pulse_per_arcsec"]);
  EXPECT_EQ(station::record_acceptance(s, run, gx200(s, run)), expected);
  EXPECT_EQ(count(s, "SELECT count(*) FROM acceptance_results"), 2);
  EXPECT_EQ(station::stored_acceptance_json(s, run), expected);
}

// Two acceptance runs of gyro SIM-0001 (seeds 1 and 2 simulate it with other scale factors):
// `history` lists each run's K and the change between them with its combined standard error,
// (K2 - K1) / K1 and sqrt(se1^2 + se2^2) / K1 in ppm; the change found is the simulated one
// within 4 of those errors, and beyond the action limit it is flagged.
TEST(AcceptanceStore, HistoryShowsTheScaleFactorsDriftBetweenTwoRuns) {
  const auto db = station::testing_support::fresh_db("acceptance_history");
  const auto r1 = station::run_simulated(short_acceptance(db, 1));
  const auto r2 = station::run_simulated(short_acceptance(db, 2));
  ASSERT_EQ(r1["state"], "completed");
  ASSERT_EQ(r2["state"], "completed");
  std::vector<station::AcceptanceRow> rows;
  {
    station::Store s(db, station::OpenMode::read_only);
    rows = station::acceptance_rows_of_serial(s, "SIM-0001");
  }
  ASSERT_EQ(rows.size(), 2u);
  const double k1 = *rows[0].sf_pulse_per_arcsec, k2 = *rows[1].sf_pulse_per_arcsec;
  const double u1 = *rows[0].sf_se_pulse_per_arcsec, u2 = *rows[1].sf_se_pulse_per_arcsec;
  const auto out = run_station("history --db " + db + " --serial SIM-0001 --json");
  ASSERT_EQ(out.status, 0) << out.out;
  const json h = json::parse(out.out);
  ASSERT_EQ(h["acceptance"].size(), 2u);
  EXPECT_EQ(h["acceptance"][1]["sf_pulse_per_arcsec"].get<double>(), k2);
  ASSERT_EQ(h["scale_factor_drift"].size(), 1u);
  const json& d = h["scale_factor_drift"][0];
  EXPECT_EQ(d["run_id"], rows[1].run_id);
  EXPECT_EQ(d["previous_run_id"], rows[0].run_id);
  EXPECT_NEAR(d["delta_ppm"].get<double>(), (k2 - k1) / k1 * 1e6, 1e-9);
  EXPECT_NEAR(d["se_ppm"].get<double>(), std::hypot(u1, u2) / k1 * 1e6, 1e-9);
  EXPECT_NEAR(d["zeta"].get<double>(), (k2 - k1) / std::hypot(u1, u2), 1e-9);
  ASSERT_EQ(r1["acceptance"][0]["serial"], "SIM-0001");
  ASSERT_EQ(r2["acceptance"][0]["serial"], "SIM-0001");
  const double t1 = r1["acceptance"][0]["ladders"][0]["true"]["sf_pulse_per_arcsec"];
  const double t2 = r2["acceptance"][0]["ladders"][0]["true"]["sf_pulse_per_arcsec"];
  EXPECT_LE(std::abs(d["delta_ppm"].get<double>() - (t2 - t1) / t1 * 1e6),
            4 * d["se_ppm"].get<double>());
  EXPECT_EQ(d["drift"].get<bool>(), std::abs(d["zeta"].get<double>()) > 3.0);
  const auto text = run_station("history --db " + db + " --serial SIM-0001");
  EXPECT_NE(text.out.find("K pulse/arcsec"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("scale factor run 2 from run 1: "), std::string::npos) << text.out;
}

// A run stopped inside its ladder: the ladder's figures cannot be computed; the run still ends
// (stopped), keeps its samples and stores why, and the serial's K column stays empty.
TEST(AcceptanceStore, ARunWhoseFiguresCannotBeComputedStillEndsWithItsSamples) {
  auto o = short_acceptance(station::testing_support::fresh_db("acceptance_stopped"), 1);
  std::atomic<bool> stop{false};
  o.stop = &stop;
  // Two power cycles take 1,260 s; at 1,300 s the ladder has measured no point.
  o.on_world_tick = [&stop](double t_s, station::sim::SimWorld&) {
    if (t_s >= 1300) stop = true;
  };
  const auto r = station::run_simulated(o);
  EXPECT_EQ(r["state"], "stopped") << r.dump();
  station::Store s(o.db_path, station::OpenMode::read_only);
  EXPECT_GT(count(s, "SELECT count(*) FROM samples"), 2 * 1290);
  const auto rows = station::acceptance_rows_of_run(s, r["run_id"]);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    const json& l = row.figures["ladders"][0];
    EXPECT_FALSE(l["ok"].get<bool>()) << l.dump();
    EXPECT_FALSE(l["error"].get<std::string>().empty());
    EXPECT_FALSE(row.sf_pulse_per_arcsec.has_value());
    EXPECT_EQ(row.pass, false);  // the part's limits name figures the run did not measure
  }
}

// The figures' table refusing every row (a trigger: what a full or broken database does): the
// run still ends completed with its samples and events, and no row is stored.
TEST(AcceptanceStore, AFailureToStoreTheFiguresDoesNotLoseTheRun) {
  const auto path = station::testing_support::fresh_db("acceptance_refused");
  {
    station::Store s(path);
    s.db().exec(
        "CREATE TRIGGER refuse BEFORE INSERT ON acceptance_results BEGIN SELECT RAISE(ABORT, "
        "'refused by the test'); END;");
  }
  const auto r = station::run_simulated(short_acceptance(path, 1));
  EXPECT_EQ(r["state"], "completed") << r.dump();
  station::Store s(path, station::OpenMode::read_only);
  EXPECT_EQ(s.find_run(r["run_id"])->state, station::RunState::completed);
  EXPECT_GT(count(s, "SELECT count(*) FROM samples"), 2 * 1800);
  EXPECT_EQ(count(s, "SELECT count(*) FROM acceptance_results"), 0);
  EXPECT_EQ(count(s, "SELECT count(*) FROM events WHERE kind = 'run_end'"), 1);
}

// A run whose figures were never stored (run before migration 12, or its end failed to store
// them): `station fit --all --run ID --acceptance` computes them by the run's end's code path,
// judged against the part its slots named (the snapshot stored with the run).
TEST(AcceptanceStore, FitAcceptanceComputesAnOlderRunsFiguresAgain) {
  const auto o = short_acceptance(station::testing_support::fresh_db("acceptance_refit"), 1);
  const std::int64_t run = station::run_simulated(o)["run_id"];
  {
    station::Store s(o.db_path);
    s.db().exec("DELETE FROM acceptance_results");
  }
  // No thermal record in this protocol: every serial's fit is skipped (exit 1), the figures are
  // computed all the same.
  const auto out = run_station("fit --db " + o.db_path + " --all --run " + std::to_string(run) +
                               " --acceptance");
  EXPECT_EQ(out.status, 1) << out.out;
  station::Store s(o.db_path);
  const json stored = station::stored_acceptance_json(s, run);
  ASSERT_EQ(stored.size(), 2u);
  EXPECT_EQ(stored, station::judged_acceptance(s, run, gx200(s, run)));
  EXPECT_EQ(stored[0]["verdict"]["part"], "GX-200");
}

// The drift between runs: each run with a K against the previous one with a K (a run without
// one skipped); zeta = dK / sqrt(u1^2 + u2^2), flagged beyond 3 (ISO 13528); K held more than
// 1 C apart named; TC's change where both runs have one.
TEST(AcceptanceHistory, DriftIsFlaggedBeyondThreeCombinedErrors) {
  const auto row = [](std::int64_t run, std::optional<double> k, double temp_c,
                      std::optional<double> tc) {
    station::AcceptanceRow r;
    r.run_id = run;
    r.sf_pulse_per_arcsec = k;
    r.sf_se_pulse_per_arcsec = 1e-6;
    r.sf_temp_c = temp_c;
    r.tc_ppm_per_c = tc;
    r.tc_se_ppm_per_c = 0.1;
    return r;
  };
  const double k = 0.6667;
  const auto d =
      station::scale_factor_drift({row(1, k, 25, 4.0), row(2, std::nullopt, 25, {}),
                                   row(3, k + 5e-6, 25, 4.2), row(4, k + 8e-6, 40, std::nullopt)});
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].run_id, 3);
  EXPECT_EQ(d[0].previous_run_id, 1);
  EXPECT_NEAR(d[0].delta_ppm, 5e-6 / k * 1e6, 1e-9);
  EXPECT_NEAR(d[0].se_ppm, std::sqrt(2.0) * 1e-6 / k * 1e6, 1e-9);
  EXPECT_NEAR(*d[0].zeta, 5.0 / std::sqrt(2.0), 1e-6);  // 3.54: beyond 3
  EXPECT_TRUE(d[0].drift);
  EXPECT_NEAR(*d[0].tc_delta_ppm_per_c, 0.2, 1e-12);
  EXPECT_NEAR(*d[0].tc_se_ppm_per_c, 0.1 * std::sqrt(2.0), 1e-12);
  EXPECT_FALSE(d[0].temp_gap_c.has_value());
  EXPECT_NEAR(*d[1].zeta, 3.0 / std::sqrt(2.0), 1e-6);  // 2.12: within
  EXPECT_FALSE(d[1].drift);
  EXPECT_FALSE(d[1].tc_delta_ppm_per_c.has_value());
  EXPECT_EQ(d[1].temp_gap_c, 15.0);
}
