// Issue 36: every power_cycles step's turn-on figures forwarded to a real PostgreSQL 15 (fleet
// schema 7, station migration 15) with their run: the central rows equal the station's, a resend
// of everything writes nothing, a recomputation that drops a step deletes it on the server, and
// `station history --pg` reads each step.
#include <gtest/gtest.h>

#include "station/fleet/fleet_acceptance.hpp"
#include "station/store/acceptance_results.hpp"
#include "station/store/store.hpp"
#include "tests/fleet/fleet_fixture.hpp"

namespace {

using station::Database;
using station::OpenMode;
namespace fleet = station::fleet;
using station::testing_support::FleetTest;
using station::testing_support::server_rows;
using station::testing_support::station_rows;

std::int64_t count(const std::string& sql) {
  fleet::PgConnection pg(FleetTest::target());
  return pg.exec(sql).integer(0, 0);
}

std::string xmins() {
  fleet::PgConnection pg(FleetTest::target());
  return pg
      .exec(
          "SELECT coalesce(string_agg(xmin::text, ',' ORDER BY run_uuid, serial, step_no), '') "
          "FROM acceptance_turn_on_steps")
      .text(0, 0);
}

class FleetTurnOnSteps : public FleetTest {
 protected:
  /// tests/report/acceptance_two_plateaus.toml on two simulated gyros: two turn-ons at room and
  /// two warm (two power_cycles steps).
  static std::string two_step_station(const std::string& name) {
    station::SimRunOptions o;
    o.db_path = station::testing_support::fresh_db(name);
    o.protocol = std::string(STATION_SOURCE_DIR) + "/tests/report/acceptance_two_plateaus.toml";
    o.progress = false;
    o.fresh = true;
    o.gyros = 2;
    o.seed = 61;
    const auto out = station::run_simulated(o);
    EXPECT_EQ(out["state"], "completed") << out.dump();
    return o.db_path;
  }
};

}  // namespace

TEST_F(FleetTurnOnSteps, EachStepArrivesEqualIsResentAsNothingAndIsReplaced) {
  const auto db = two_step_station("fleet_turn_on_steps");
  const auto sent = forward_all(db, false);
  EXPECT_EQ(sent.failed, 0) << sent.last_error;
  const auto& t = fleet::fleet_table("acceptance_turn_on_steps");
  const auto local = station_rows(db, t);
  ASSERT_EQ(local.size(), 4u) << "two steps per gyro";
  EXPECT_EQ(server_rows(t), local);
  EXPECT_EQ(count("SELECT count(DISTINCT label) FROM acceptance_turn_on_steps WHERE ok = 1 AND "
                  "repeatability_dph > 0"),
            2);

  // Every acknowledgement forgotten: a resend of everything writes no row.
  const std::string before = xmins();
  {
    Database w(db, OpenMode::existing);
    w.exec("UPDATE fleet_outbox SET acked = 0, events_acked_id = NULL");
  }
  const auto all = forward_all(db, false);
  EXPECT_EQ(all.failed, 0) << all.last_error;
  EXPECT_EQ(all.rows, 0) << "a resend of everything wrote rows";
  EXPECT_EQ(xmins(), before);

  // `station history --pg`: each step of a serial, as the station reads it.
  std::string serial;
  {
    station::Store store(db, OpenMode::read_only);
    serial = station::acceptance_rows_of_run(store, 1).at(1).serial;
  }
  {
    fleet::PgConnection pg(target());
    const auto central = fleet::fleet_acceptance_rows_of_serial(pg, serial);
    ASSERT_TRUE(central && central->size() == 1u);
    ASSERT_EQ(central->front().turn_on_steps.size(), 2u);
    EXPECT_EQ(central->front().turn_on_steps[1].label, "turn-ons, warm");
  }

  // `station fleet`: each result lists its steps (JSON and text), as the station stored them.
  {
    fleet::PgConnection pg(target());
    const auto points = fleet::fleet_acceptance_points(pg, {});
    ASSERT_EQ(points.size(), 2u);
    station::Store store(db, OpenMode::read_only);
    const auto rows = station::acceptance_rows_of_run(store, 1);
    for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(points[i].turn_on_steps, rows[i].turn_on_steps);
    const auto j = fleet::fleet_acceptance_json(points);
    const auto& listed = j["parts"][0]["results_list"][1]["turn_on_steps"];
    ASSERT_EQ(listed.size(), 2u) << j.dump();
    EXPECT_EQ(listed[1]["repeatability_dph"].get<double>(),
              *rows[1].turn_on_steps[1].repeatability_dph);
    const std::string text = fleet::fleet_acceptance_text(j);
    const std::string want = "  turn-on " + points[1].station + " " + rows[1].serial + " run " +
                             std::to_string(points[1].run_fleet_id) + " " +
                             station::turn_on_step_name(rows[1].turn_on_steps[1]) + ": sigma ";
    EXPECT_NE(text.find(want), std::string::npos) << want << "\n" << text;
  }

  // A recomputation without the second step (a protocol edited, say): the server drops it.
  {
    station::Store store(db);
    auto rows = station::acceptance_rows_of_run(store, 1);
    for (auto& r : rows) r.turn_on_steps.pop_back();
    station::replace_acceptance_rows(store, 1, rows);
  }
  const auto again = forward_all(db, false);
  EXPECT_EQ(again.failed, 0) << again.last_error;
  EXPECT_EQ(count("SELECT count(*) FROM acceptance_turn_on_steps"), 2);
  EXPECT_EQ(server_rows(t), station_rows(db, t));
}

// A server at schema 6 (acceptance_results, no steps table): `station fleet` lists its results
// without steps rather than failing; the station refuses to forward to it until `sync --init`,
// after which the steps arrive.
TEST_F(FleetTurnOnSteps, AServerAtSchema6ListsResultsWithoutStepsAndIsMigratedForThem) {
  const auto db = two_step_station("fleet_turn_on_steps_v6");
  EXPECT_EQ(forward_all(db, false).failed, 0);
  {
    fleet::PgConnection pg(target());
    pg.exec("DROP TABLE acceptance_turn_on_steps");
    pg.exec("DELETE FROM fleet_schema WHERE version >= 7");
    const auto points = fleet::fleet_acceptance_points(pg, {});
    ASSERT_EQ(points.size(), 2u);
    EXPECT_TRUE(points[0].turn_on_steps.empty());
    EXPECT_EQ(
        fleet::fleet_schema_problem(fleet::server_schema_version(pg), fleet::fleet_schema_version())
            .value_or(""),
        "fleet schema version 6 is older than this station's 7; refusing to forward "
        "(migrate the server with `station sync --init`)");
    fleet::init_fleet_schema(pg);
  }
  {
    Database w(db, OpenMode::existing);
    w.exec("UPDATE fleet_outbox SET acked = 0");  // as a station whose pass was refused
  }
  EXPECT_EQ(forward_all(db, false).failed, 0);
  const auto& t = fleet::fleet_table("acceptance_turn_on_steps");
  EXPECT_EQ(server_rows(t).size(), 4u);
  EXPECT_EQ(server_rows(t), station_rows(db, t));
}
