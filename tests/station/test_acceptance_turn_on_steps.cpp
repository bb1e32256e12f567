// Issue 36: every power_cycles step's turn-on figures stored (migration 15), read back, shown by
// `station history`. A database at migration 13 or 14 upgrades, its stored figures' steps taken
// from their JSON by the migration exactly as acceptance_row takes them, and the runs pending in
// the outbox again once; a run with two power_cycles steps stores both, a recomputation replaces
// them.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <set>
#include <string>

#include "schemas/migrations.hpp"
#include "station/acceptance/acceptance_record.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/acceptance_results.hpp"
#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using nlohmann::json;

/// The place of migration 15 among the embedded migrations (its number minus one when 14 is
/// there): the version a database has just before it.
std::size_t index_of_migration_15() {
  for (std::size_t i = 0; i < station::schemas::kMigrations.size(); ++i)
    if (std::string(station::schemas::kMigrations[i].first).rfind("015_", 0) == 0) return i;
  ADD_FAILURE() << "no migration 015_*";
  return 0;
}

// Three serials as stored before migration 15: two power_cycles steps (the second not computed),
// one step (its turn_on alone), and no power cycles.
const json kSerials = json::parse(R"([
  {"serial": "A", "ladders": [], "positions": [],
   "turn_on": {"ok": true, "turn_ons": 3, "repeatability_dph": 0.004,
               "repeatability_lower_dph": 0.0021, "repeatability_upper_dph": 0.025,
               "max_warmup_s": 120, "biases_dph": [0.1, 0.104, 0.097]},
   "turn_on_steps": [
     {"ok": true, "step_index": 1, "label": "cold", "temp_c": -39.96, "turn_ons": 3,
      "repeatability_dph": 0.004, "repeatability_lower_dph": 0.0021,
      "repeatability_upper_dph": 0.025, "max_warmup_s": 120},
     {"ok": false, "error": "turn-on 1: too short", "step_index": 7, "label": "hot",
      "temp_c": 70.02}]},
  {"serial": "B", "ladders": [], "positions": [],
   "turn_on": {"ok": true, "turn_ons": 2, "repeatability_dph": 0.01,
               "repeatability_lower_dph": 0.0045, "repeatability_upper_dph": 0.32,
               "max_warmup_s": null}},
  {"serial": "C", "ladders": [], "positions": []}])");

}  // namespace

TEST(AcceptanceTurnOnSteps, TheRowsStepsAreEachPowerCyclesStepInOrder) {
  const auto a = station::turn_on_step_rows(kSerials[0]);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].step_no, 1);
  EXPECT_EQ(a[0].step_index, 1);
  EXPECT_EQ(a[0].label, "cold");
  EXPECT_EQ(a[0].temp_c, -39.96);
  EXPECT_TRUE(a[0].ok);
  EXPECT_EQ(a[0].turn_ons, 3);
  EXPECT_EQ(a[0].repeatability_upper_dph, 0.025);
  EXPECT_EQ(a[1].step_no, 2);
  EXPECT_FALSE(a[1].ok);
  EXPECT_EQ(a[1].error, "turn-on 1: too short");
  EXPECT_FALSE(a[1].repeatability_dph.has_value());
  EXPECT_EQ(station::turn_on_step_name(a[1]), "'hot' (step 8, 70.0 C)");
  const auto b = station::turn_on_step_rows(kSerials[1]);  // one step: its turn_on
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].step_no, 1);
  EXPECT_FALSE(b[0].step_index.has_value());
  EXPECT_FALSE(b[0].max_warmup_s.has_value());  // none settled
  EXPECT_EQ(station::turn_on_step_name(b[0]), "");
  EXPECT_TRUE(station::turn_on_step_rows(kSerials[2]).empty());
}

// A database just before migration 15 (version 13, and 14 where it exists) with figures stored
// and forwarded: the next writer migrates it; each row's steps are what acceptance_row gives
// from its JSON; the runs are pending again once (their steps travel); rows written afterwards
// carry their steps.
TEST(AcceptanceTurnOnSteps, MigrationFifteenTakesTheStoredRowsStepsAndTheyTravelOnce) {
  const std::size_t before = index_of_migration_15();
  for (const std::size_t version : std::set<std::size_t>{13, before}) {
    SCOPED_TRACE(version);
    const auto path =
        station::testing_support::fresh_db("turn_on_steps_v" + std::to_string(version));
    {
      station::Database db(path);
      for (std::size_t i = 0; i < version; ++i) db.exec(station::schemas::kMigrations[i].second);
      db.exec("PRAGMA user_version = " + std::to_string(version));
      db.exec(
          "INSERT INTO runs (id, started_utc, state, protocol_name, protocol_text, config_text, "
          "software_version, station) VALUES (1, 'x', 'completed', 'p', '', '', '0.1', 'rig')");
      for (const auto& s : kSerials) {
        auto ins = db.prepare(
            "INSERT INTO acceptance_results (run_id, serial, computed_utc, figures_json) VALUES "
            "(1, ?, 'then', ?)");
        ins.bind(1, s["serial"].get<std::string>()).bind(2, s.dump());
        ins.step();
      }
      db.exec("UPDATE fleet_outbox SET acked = changes");  // forwarded before the upgrade
    }
    station::Store s(path);
    ASSERT_GT(s.db().schema_version(), static_cast<int>(before));
    const auto rows = station::acceptance_rows_of_run(s, 1);
    ASSERT_EQ(rows.size(), 3u);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      SCOPED_TRACE(rows[i].serial);
      EXPECT_EQ(rows[i].turn_on_steps, station::turn_on_step_rows(kSerials[i]));
    }
    EXPECT_EQ(rows[0].turn_on_steps.size(), 2u);
    auto pending = s.db().prepare(
        "SELECT count(*) FROM fleet_outbox WHERE item = 'run' AND local_id = 1 AND changes > "
        "acked");
    ASSERT_TRUE(pending.step());
    EXPECT_EQ(pending.column_int(0), 1) << "the run's steps would never travel";
    // Rows written now carry their steps; a rewrite replaces them, never adds.
    std::vector<station::AcceptanceRow> again;
    for (const auto& x : kSerials) again.push_back(station::acceptance_row(1, x));
    station::replace_acceptance_rows(s, 1, again);
    station::replace_acceptance_rows(s, 1, again);
    auto n = s.db().prepare("SELECT count(*) FROM acceptance_turn_on_steps");
    ASSERT_TRUE(n.step());
    EXPECT_EQ(n.column_int(0), 3);
    // A serial no longer computed takes its steps with it (the foreign key's cascade too).
    again.erase(again.begin());
    station::replace_acceptance_rows(s, 1, again);
    n.reset();
    ASSERT_TRUE(n.step());
    EXPECT_EQ(n.column_int(0), 1);
  }
}

// Steps that are not objects (a string, a number, null) are no steps, in the migration as in
// acceptance_row (review 2026-11-29: a string element made json_type() read its bare text and
// the migration abort, "malformed JSON", the file left at version 13).
TEST(AcceptanceTurnOnSteps, MigrationFifteenSkipsStepsThatAreNotObjects) {
  const json odd = json::parse(R"({"serial": "D", "ladders": [], "positions": [],
    "turn_on_steps": ["junk", 3, null, {"ok": false, "error": "e", "step_index": 2}]})");
  const auto path = station::testing_support::fresh_db("turn_on_steps_odd");
  {
    station::Database db(path);
    for (std::size_t i = 0; i < 13; ++i) db.exec(station::schemas::kMigrations[i].second);
    db.exec("PRAGMA user_version = 13");
    db.exec(
        "INSERT INTO runs (id, started_utc, state, protocol_name, protocol_text, config_text, "
        "software_version, station) VALUES (1, 'x', 'completed', 'p', '', '', '0.1', 'rig')");
    auto ins = db.prepare(
        "INSERT INTO acceptance_results (run_id, serial, computed_utc, figures_json) VALUES "
        "(1, 'D', 'then', ?)");
    ins.bind(1, odd.dump());
    ins.step();
  }
  station::Store s(path);
  const auto rows = station::acceptance_rows_of_run(s, 1);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].turn_on_steps, station::turn_on_step_rows(odd));
  EXPECT_EQ(rows[0].turn_on_steps.size(), 1u);
}

// A simulated run with a power_cycles block at room and one warm: both stored, each equal to its
// object of the run's judged JSON; `station history --json` lists both.
TEST(AcceptanceTurnOnSteps, ARunsTwoPowerCyclesStepsAreStoredAndShownByHistory) {
  station::SimRunOptions o;
  o.db_path = station::testing_support::fresh_db("turn_on_steps_run");
  o.protocol = std::string(STATION_SOURCE_DIR) + "/tests/report/acceptance_two_plateaus.toml";
  o.progress = false;
  o.fresh = true;
  o.gyros = 1;
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  std::string serial;
  {
    station::Store s(o.db_path, station::OpenMode::read_only);
    const auto rows = station::acceptance_rows_of_run(s, r["run_id"].get<std::int64_t>());
    ASSERT_EQ(rows.size(), 1u);
    serial = rows[0].serial;
    const auto& steps = rows[0].turn_on_steps;
    ASSERT_EQ(steps.size(), 2u);
    EXPECT_EQ(steps, station::turn_on_step_rows(rows[0].figures));
    EXPECT_EQ(steps[0].label, "turn-ons, room");
    EXPECT_EQ(steps[1].label, "turn-ons, warm");
    ASSERT_TRUE(steps[0].ok && steps[1].ok) << rows[0].figures.dump();
    ASSERT_TRUE(steps[0].temp_c && steps[1].temp_c);
    EXPECT_GT(*steps[1].temp_c - *steps[0].temp_c, 5.0);  // the second block warm (35 C)
    // The first step's columns are as before.
    EXPECT_EQ(rows[0].turn_on_repeatability_dph, steps[0].repeatability_dph);
  }
  const std::string cmd = std::string(STATION_BINARY_DIR) + "/station/station history --db " +
                          o.db_path + " --serial " + serial + " --json 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = fread(buf.data(), 1, buf.size(), p)) > 0;) out.append(buf.data(), n);
  ASSERT_EQ(WEXITSTATUS(pclose(p)), 0) << out;
  const json h = json::parse(out);
  const json& steps = h["acceptance"][0]["turn_on_steps"];
  ASSERT_EQ(steps.size(), 2u) << h["acceptance"].dump();
  EXPECT_EQ(steps[1]["label"], "turn-ons, warm");
  EXPECT_EQ(steps[1]["step_no"], 2);
  EXPECT_TRUE(steps[1]["repeatability_dph"].is_number());
}
