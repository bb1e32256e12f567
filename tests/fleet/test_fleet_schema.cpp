// The fleet's table list (station/fleet/fleet_tables.cpp) against both schemas it joins: every
// column of a forwarded SQLite table travels (or is named as translated), every central column
// exists on a migrated server; the schema version rule; [fleet] in the configuration.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "station/config/config.hpp"
#include "station/store/store.hpp"
#include "tests/fleet/fleet_fixture.hpp"

namespace {

namespace fleet = station::fleet;
using station::testing_support::FleetTest;

// SQLite columns that travel under another name (the central key is a uuid, not a local id).
const std::map<std::string, std::string> kRenamed = {
    {"id", "local_id"}, {"run_id", "run_uuid"}, {"fit_id", "fit_uuid"}};

std::set<std::string> sqlite_columns(station::Database& db, const std::string& table) {
  std::set<std::string> out;
  auto st = db.prepare("SELECT name FROM pragma_table_info(?)");
  st.bind(1, table);
  while (st.step()) out.insert(st.column_text(0));
  return out;
}

TEST(FleetTables, EveryStationColumnTravels) {
  const auto path = station::testing_support::fresh_db("fleet_columns");
  station::Store store(path);  // migrated to the newest schema
  station::Database db(path, station::OpenMode::read_only);
  for (const auto& t : fleet::fleet_tables()) {
    const auto central = fleet::split_columns(t.columns);
    const std::set<std::string_view> have(central.begin(), central.end());
    for (const auto& c : sqlite_columns(db, std::string(t.name))) {
      const auto renamed = kRenamed.find(c);
      const std::string name = renamed != kRenamed.end() ? renamed->second : c;
      EXPECT_TRUE(have.count(name)) << t.name << "." << c << " does not travel to the fleet";
    }
    // The SELECT yields exactly the listed columns.
    auto st = db.prepare(t.select);
    EXPECT_EQ(st.column_count(), static_cast<int>(central.size())) << t.name;
  }
}

class FleetSchema : public FleetTest {};

TEST_F(FleetSchema, EveryCentralColumnExistsOnAMigratedServer) {
  fleet::PgConnection pg(target());
  EXPECT_EQ(fleet::server_schema_version(pg), fleet::fleet_schema_version());
  for (const auto& t : fleet::fleet_tables()) {
    for (const auto& c : fleet::split_columns(t.columns)) {
      auto r = pg.exec(
          "SELECT count(*) FROM information_schema.columns WHERE table_name = $1 AND "
          "column_name = $2",
          {std::string(t.name), std::string(c)});
      EXPECT_EQ(r.integer(0, 0), 1) << t.name << "." << c;
    }
  }
  // --init again is a no-op.
  EXPECT_EQ(fleet::init_fleet_schema(pg), fleet::fleet_schema_version());
}

// Issue 34 point 7a: a table dropped on the server while the version row stays. The station
// refuses to forward naming it; `--init` re-creates exactly it, with its indexes, and again
// re-creates nothing.
TEST_F(FleetSchema, InitReCreatesADroppedTableAndTheStationNamesIt) {
  fleet::PgConnection pg(target());
  pg.exec("DROP TABLE events");
  try {
    fleet::require_fleet_schema(pg);
    ADD_FAILURE() << "a server without its events table was accepted";
  } catch (const fleet::PgError& e) {
    EXPECT_NE(std::string(e.what()).find("table events missing"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--init"), std::string::npos) << e.what();
  }
  std::vector<std::string> recreated;
  EXPECT_EQ(fleet::init_fleet_schema(pg, &recreated), fleet::fleet_schema_version());
  EXPECT_EQ(recreated, std::vector<std::string>{"events"});
  EXPECT_NO_THROW(fleet::require_fleet_schema(pg));
  for (const auto& c : fleet::split_columns(fleet::fleet_table("events").columns)) {
    auto r = pg.exec(
        "SELECT count(*) FROM information_schema.columns WHERE table_schema = current_schema() "
        "AND table_name = 'events' AND column_name = $1",
        {std::string(c)});
    EXPECT_EQ(r.integer(0, 0), 1) << "events." << c;
  }
  EXPECT_EQ(
      pg.exec("SELECT count(*) FROM pg_namespace WHERE nspname LIKE 'fleet_init%'").integer(0, 0),
      0)
      << "the scratch schema is left behind";
  EXPECT_EQ(fleet::init_fleet_schema(pg, &recreated), fleet::fleet_schema_version());
  EXPECT_TRUE(recreated.empty());
  // A table of a later version than the server's is migrated, not mended: drop stations (4) and
  // say the server is at 3: --init runs migrations 4 and 5 (5 adds a column that is there: IF NOT
  // EXISTS).
  pg.exec("DROP TABLE stations");
  pg.exec("DELETE FROM fleet_schema WHERE version >= 4");  // and every later one
  EXPECT_EQ(fleet::init_fleet_schema(pg, &recreated), 3);
  EXPECT_TRUE(recreated.empty());
  EXPECT_TRUE(fleet::missing_fleet_tables(pg).empty());
}

TEST_F(FleetSchema, AnOlderServerIsRefusedInOneLineANewerOneAccepted) {
  fleet::PgConnection pg(target());
  pg.exec("DELETE FROM fleet_schema");
  pg.exec("INSERT INTO fleet_schema (version) VALUES (0)");
  try {
    fleet::require_fleet_schema(pg);
    ADD_FAILURE() << "an older server was accepted";
  } catch (const fleet::PgError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no fleet schema"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  pg.exec("INSERT INTO fleet_schema (version) VALUES (99)");
  EXPECT_NO_THROW(fleet::require_fleet_schema(pg));
  // A server one version behind a station: refused, saying both versions.
  const auto older = fleet::fleet_schema_problem(1, 2);
  ASSERT_TRUE(older.has_value());
  EXPECT_NE(older->find("version 1 is older than this station's 2"), std::string::npos) << *older;
  EXPECT_FALSE(fleet::fleet_schema_problem(3, 2).has_value());
}

TEST_F(FleetSchema, AnUnreachableServerIsAnErrorNotAHang) {
  fleet::PgTarget t{"postgresql:///postgres?host=/nonexistent-dir&user=station", {}, 2};
  EXPECT_THROW(fleet::PgConnection pg(t), fleet::PgError);
}

constexpr const char* kRig = R"(
[station]
latitude_deg = 39.9
{name}
[chamber]
endpoint = "tcp://127.0.0.1:15020"
model = "generic_plc"
[can]
transport = "unix:/tmp/x"
[[slot]]
node = 1
serial = "A1"
[fleet]
{fleet}
)";

std::string rig(const std::string& name, const std::string& fleet) {
  std::string s = kRig;
  s.replace(s.find("{name}"), 6, name);
  s.replace(s.find("{fleet}"), 7, fleet);
  return s;
}

TEST(FleetConfig, ReadsTheTableAndRefusesCredentials) {
  const auto c = station::parse_station_config(
      rig("name = \"rig-3\"",
          "pg = \"postgresql://fleet@db.example/line\"\npassword_file = \"pgpass\"\n"
          "sslmode = \"verify-full\"\nsamples = true"),
      "/etc/gyro-station/station.toml");
  ASSERT_TRUE(c.fleet.has_value());
  EXPECT_TRUE(c.fleet->samples);
  const std::vector<std::pair<std::string, std::string>> want = {
      {"passfile", "/etc/gyro-station/pgpass"}, {"sslmode", "verify-full"}};
  EXPECT_EQ(c.fleet->keywords, want);
  const auto refused = [](const std::string& text, const std::string& says) {
    try {
      station::parse_station_config(text, "rig.toml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const station::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  refused(rig("name = \"rig-3\"", "pg = \"postgresql://fleet:secret@db/line\""), "password");
  refused(rig("name = \"rig-3\"", "pg = \"host=db password=secret\""), "password");
  refused(rig("name = \"rig-3\"", "pg = \"postgresql://db/line\"\nsslmode = \"maybe\""), "sslmode");
  refused(rig("", "pg = \"postgresql://db/line\""), "[station] name");
  refused(rig("name = \"rig-3\"", "pg = \"postgresql://db/line\"\nuser = \"x\""), "user");
}

}  // namespace
