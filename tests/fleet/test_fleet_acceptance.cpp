// Issue 36: a run's acceptance figures forwarded to a real PostgreSQL 15 (the throw-away server
// per test process) and charted by `station fleet`. A simulated acceptance run's rows arrive equal
// to the station's; a recomputation replaces them (a serial no longer computed is deleted); a
// commit whose answer is lost, and acknowledgements lost to a kill, are settled by a resend that
// writes nothing; a result without K says why, never a zero.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "station/acceptance/acceptance_record.hpp"
#include "station/fleet/fleet_acceptance.hpp"
#include "station/fleet/fleet_page.hpp"
#include "station/store/acceptance_results.hpp"
#include "station/store/store.hpp"
#include "tests/fleet/fleet_fixture.hpp"
#include "tests/fleet/pg_proxy.hpp"

namespace {

using nlohmann::json;
using station::Database;
using station::OpenMode;
namespace fleet = station::fleet;
using station::testing_support::FleetTest;
using station::testing_support::PgProxy;
using station::testing_support::query_message;
using station::testing_support::server_rows;
using station::testing_support::station_rows;

const std::string kParts = std::string(STATION_SOURCE_DIR) + "/station/parts/example_parts.toml";

std::int64_t count(const std::string& sql) {
  fleet::PgConnection pg(FleetTest::target());
  return pg.exec(sql).integer(0, 0);
}

std::string xmins() {
  fleet::PgConnection pg(FleetTest::target());
  return pg
      .exec(
          "SELECT coalesce(string_agg(xmin::text, ',' ORDER BY run_uuid, serial), '') FROM "
          "acceptance_results")
      .text(0, 0);
}

class FleetAcceptance : public FleetTest {
 protected:
  /// tests/report/acceptance_two_plateaus.toml on two simulated GX-200 gyros (turn-ons, a
  /// ladder and positions at room, a ladder warm: K at 25 C and its temperature coefficient),
  /// ~1.4 h simulated.
  static std::string acceptance_station(const std::string& name, std::uint64_t seed) {
    station::SimRunOptions o;
    o.db_path = station::testing_support::fresh_db(name);
    o.protocol = std::string(STATION_SOURCE_DIR) + "/tests/report/acceptance_two_plateaus.toml";
    o.progress = false;
    o.fresh = true;
    o.gyros = 2;
    o.seed = seed;
    o.parts_path = kParts;
    o.part_number = "GX-200";
    const auto out = station::run_simulated(o);
    EXPECT_EQ(out["state"], "completed") << out.dump();
    return o.db_path;
  }
  static fleet::ForwardOptions options() { return {.samples = false, .station = "test"}; }
};

TEST_F(FleetAcceptance, ARunsFiguresArriveEqualToTheStationsRowsAndAreCharted) {
  const auto db = acceptance_station("fleet_acceptance_rows", 51);
  const auto sent = forward_all(db, false);
  EXPECT_EQ(sent.failed, 0) << sent.last_error;
  const auto& t = fleet::fleet_table("acceptance_results");
  const auto local = station_rows(db, t);
  ASSERT_EQ(local.size(), 2u) << "a row per gyro";
  EXPECT_EQ(server_rows(t), local);
  EXPECT_EQ(fleet::Forwarder(db, target(), options()).backlog().items, 0);

  // What `station fleet` charts: the stored K and TC with their SEs, for part GX-200.
  station::Store store(db, OpenMode::read_only);
  const auto rows = station::acceptance_rows_of_run(store, 1);
  fleet::PgConnection pg(target());
  const json j = fleet::fleet_acceptance_json(fleet::fleet_acceptance_points(pg, {}));
  ASSERT_EQ(j["parts"].size(), 1u) << j.dump();
  const json& part = j["parts"][0];
  EXPECT_EQ(part["part"], "GX-200");
  EXPECT_EQ(part["results"], 2);
  ASSERT_EQ(part["charts"].size(), 2u);
  const json& k = part["charts"][0];
  const json& tc = part["charts"][1];
  EXPECT_EQ(k["unit"], "pulse/arcsec");
  EXPECT_EQ(tc["unit"], "ppm/C");
  ASSERT_EQ(k["points"].size(), 2u);
  ASSERT_EQ(tc["points"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE(rows[i].serial);
    const json& p = k["points"][i];
    EXPECT_EQ(p["serial"], rows[i].serial);
    EXPECT_EQ(p["x"], i + 1);
    // The exact stored doubles: the COPY text is the shortest that reads back the same.
    EXPECT_EQ(p["value"].get<double>(), *rows[i].sf_pulse_per_arcsec);
    EXPECT_EQ(p["se"].get<double>(), *rows[i].sf_se_pulse_per_arcsec);
    EXPECT_EQ(p["held_temp_c"].get<double>(), 25.0) << "K held at the model's T_ref";
    EXPECT_TRUE(p["in_limits_chart"].get<bool>());
    EXPECT_GT(p["se"].get<double>(), 0);
    EXPECT_EQ(tc["points"][i]["value"].get<double>(), *rows[i].tc_ppm_per_c);
    EXPECT_EQ(tc["points"][i]["se"].get<double>(), *rows[i].tc_se_ppm_per_c);
    EXPECT_TRUE(part["results_list"][i]["sf_missing"].is_null());
    EXPECT_EQ(part["results_list"][i]["pass"], *rows[i].pass);
  }
  // Two results of one station: limits from their one moving range (ISO 7870-2).
  ASSERT_TRUE(k["overall"].is_object());
  EXPECT_NEAR(k["overall"]["centre"].get<double>(),
              (*rows[0].sf_pulse_per_arcsec + *rows[1].sf_pulse_per_arcsec) / 2, 1e-15);
  // The part filter and --since select them, or none.
  EXPECT_EQ(fleet::fleet_acceptance_points(pg, {.part = "GX-200", .since = std::nullopt}).size(),
            2u);
  EXPECT_TRUE(
      fleet::fleet_acceptance_points(pg, {.part = "GX-200-A", .since = std::nullopt}).empty());
  EXPECT_TRUE(
      fleet::fleet_acceptance_points(pg, {.part = std::nullopt, .since = "2999-01-01"}).empty());
  // What `station history --pg` reads: the same row as the station's, under the fleet's run id.
  const auto central = fleet::fleet_acceptance_rows_of_serial(pg, rows[1].serial);
  ASSERT_TRUE(central.has_value());
  ASSERT_EQ(central->size(), 1u);
  const auto& c = central->front();
  EXPECT_EQ(c.run_id, k["points"][1]["run_fleet_id"].get<long long>());
  EXPECT_EQ(c.computed_utc, rows[1].computed_utc);
  EXPECT_EQ(c.sf_pulse_per_arcsec, rows[1].sf_pulse_per_arcsec);
  EXPECT_EQ(c.tc_se_ppm_per_c, rows[1].tc_se_ppm_per_c);
  EXPECT_EQ(c.pass, rows[1].pass);
  EXPECT_TRUE(fleet::fleet_acceptance_rows_of_serial(pg, "no-such-serial")->empty());
}

// `station fit --acceptance` computes a run's figures again (record_acceptance, its code path):
// here without limits, so no verdict. The central rows are replaced, not added to; a serial the
// station no longer has a row for is deleted on the server.
TEST_F(FleetAcceptance, ARecomputationReplacesTheCentralRows) {
  const auto db = acceptance_station("fleet_acceptance_recompute", 52);
  forward_all(db, false);
  const auto& t = fleet::fleet_table("acceptance_results");
  EXPECT_EQ(count("SELECT count(*) FROM acceptance_results WHERE pass IS NOT NULL"), 2);
  {
    station::Store store(db);
    station::record_acceptance(store, 1, {});
  }
  auto again = forward_all(db, false);
  EXPECT_EQ(again.failed, 0) << again.last_error;
  EXPECT_GE(again.rows, 2);
  EXPECT_EQ(server_rows(t), station_rows(db, t));
  EXPECT_EQ(count("SELECT count(*) FROM acceptance_results WHERE pass IS NULL AND part_number "
                  "IS NULL"),
            2);
  // Without a verdict the part is the slot's: still charted under GX-200, judged by none.
  fleet::PgConnection pg(target());
  const auto points = fleet::fleet_acceptance_points(pg, {.part = "GX-200", .since = std::nullopt});
  ASSERT_EQ(points.size(), 2u);
  EXPECT_FALSE(points[0].pass.has_value());
  {
    station::Store store(db);
    auto rows = station::acceptance_rows_of_run(store, 1);
    rows.pop_back();
    station::replace_acceptance_rows(store, 1, rows);
  }
  again = forward_all(db, false);
  EXPECT_EQ(again.failed, 0) << again.last_error;
  EXPECT_EQ(count("SELECT count(*) FROM acceptance_results"), 1);
  EXPECT_EQ(server_rows(t), station_rows(db, t));
}

// The server commits the run with its figures; its answer is lost (as a kill between the commit
// and the outbox's acknowledgement). Nothing is acknowledged; the resend writes nothing, and
// neither does a resend of everything after the outbox forgot its acknowledgements.
TEST_F(FleetAcceptance, ALostCommitAndLostAcknowledgementsAreSettledByAResendThatWritesNothing) {
  const auto db = acceptance_station("fleet_acceptance_lost", 53);
  {
    PgProxy proxy(server_->dir());
    proxy.swallow_replies_after(query_message("COMMIT"));
    fleet::Forwarder f(db, {proxy.url(db_), {}, fleet::kPgConnectTimeoutS, 1.0}, options());
    EXPECT_THROW(f.pass(1), fleet::PgTimeout);
  }
  ASSERT_EQ(count("SELECT count(*) FROM acceptance_results"), 2) << "the server committed";
  EXPECT_GT(fleet::Forwarder(db, target(), options()).backlog().runs, 0)
      << "acknowledged without the server's answer";
  const std::string before = xmins();
  const auto resend = forward_all(db, false);
  EXPECT_EQ(resend.failed, 0) << resend.last_error;
  EXPECT_EQ(xmins(), before) << "a resend rewrote the figures";
  EXPECT_EQ(fleet::Forwarder(db, target(), options()).backlog().items, 0);
  {
    Database w(db, OpenMode::existing);
    w.exec("UPDATE fleet_outbox SET acked = 0, events_acked_id = NULL");
  }
  const auto all = forward_all(db, false);
  EXPECT_EQ(all.failed, 0) << all.last_error;
  EXPECT_EQ(all.rows, 0) << "a resend of everything wrote rows";
  EXPECT_EQ(xmins(), before);
  EXPECT_EQ(count("SELECT count(*) FROM acceptance_results"), 2);
}

// A station file whose figures were stored before migration 13 (and whose runs were forwarded):
// the migration makes those runs pending once, so their figures travel.
TEST_F(FleetAcceptance, FiguresStoredBeforeMigration13TravelOnce) {
  const auto db = acceptance_station("fleet_acceptance_v12", 54);
  {
    Database w(db, OpenMode::existing);
    for (const char* t : {"insert", "update", "delete"})
      w.exec(std::string("DROP TRIGGER outbox_acceptance_") + t);
    w.exec("UPDATE fleet_outbox SET acked = changes");  // as forwarded by a version-12 station
    // Migration 13 as the station applies it (the file it embeds).
    std::ifstream in(std::string(STATION_SOURCE_DIR) +
                     "/schemas/migrations/013_acceptance_outbox.sql");
    std::stringstream sql;
    sql << in.rdbuf();
    ASSERT_FALSE(sql.str().empty());
    w.exec(sql.str());
  }
  fleet::Forwarder f(db, target(), options());
  EXPECT_EQ(f.backlog().runs, 1);
  forward_all(db, false);
  EXPECT_EQ(count("SELECT count(*) FROM acceptance_results"), 2);
}

// A fleet server not migrated since schema 5 (no acceptance table): `station fleet` still draws
// its thermal charts and says, in its JSON, text and page, why no acceptance figure is there
// (it failed with the server's "relation does not exist" before).
TEST_F(FleetAcceptance, AServerAtSchema5SaysWhyItHasNoAcceptanceFigures) {
  {
    fleet::PgConnection pg(target());
    pg.exec("DROP TABLE acceptance_results");
    pg.exec("DROP TABLE acceptance_turn_on_steps");  // schema 7's
    pg.exec("DELETE FROM fleet_schema WHERE version >= 6");
  }
  fleet::PgConnection pg(target());
  const json j = fleet::fleet_acceptance_charts(pg, {});
  EXPECT_TRUE(j["parts"].empty());
  EXPECT_EQ(j["unavailable"],
            "the fleet database (schema version 5) has no acceptance table yet: migrate it with "
            "`station sync --init`");
  EXPECT_NE(fleet::fleet_acceptance_text(j).find("acceptance figures: the fleet database"),
            std::string::npos);
  json charts{{"parts", json::array()}, {"acceptance", j}};
  EXPECT_NE(
      fleet::fleet_html(charts, "all", station::report::Assets{}).find("acceptance-unavailable"),
      std::string::npos);
  EXPECT_FALSE(fleet::fleet_acceptance_rows_of_serial(pg, "any").has_value());
  fleet::init_fleet_schema(pg);  // migrated: the table is back and the reason gone
  EXPECT_FALSE(fleet::fleet_acceptance_charts(pg, {}).contains("unavailable"));
}

// A serial whose ladder was not computed: no K point and no zero, the ladder's own error said
// in the JSON, the text and the page; TC's reason from the same ladders.
TEST_F(FleetAcceptance, AResultWithoutKSaysWhyAndIsNotDrawnAsAZero) {
  const auto db = acceptance_station("fleet_acceptance_missing", 55);
  {
    station::Store store(db);
    auto rows = station::acceptance_rows_of_run(store, 1);
    json s = rows[1].figures;
    for (auto& l : s["ladders"])
      l = {{"label", l["label"]}, {"ok", false}, {"error", "3 of 4 points not measured"}};
    s.erase("sf_vs_temp");
    rows[1] = station::acceptance_row(1, s);
    rows[1].computed_utc = rows[0].computed_utc;
    station::replace_acceptance_rows(store, 1, rows);
  }
  forward_all(db, false);
  fleet::PgConnection pg(target());
  const json j = fleet::fleet_acceptance_json(fleet::fleet_acceptance_points(pg, {}));
  const json& part = j["parts"][0];
  EXPECT_EQ(part["results"], 2);
  EXPECT_EQ(part["charts"][0]["points"].size(), 1u) << "no zero drawn for the missing K";
  EXPECT_EQ(part["charts"][1]["points"].size(), 1u);
  const json& r = part["results_list"][1];
  EXPECT_TRUE(r["sf_pulse_per_arcsec"].is_null());
  EXPECT_EQ(r["sf_missing"],
            "scale factor, room: 3 of 4 points not measured; scale factor, warm: 3 of 4 points "
            "not measured");
  EXPECT_EQ(r["tc_missing"], r["sf_missing"]);
  const std::string text = fleet::fleet_acceptance_text(j);
  EXPECT_NE(text.find("K not computed: "), std::string::npos) << text;
  EXPECT_NE(text.find("3 of 4 points not measured"), std::string::npos) << text;
  json charts{{"parts", json::array()}, {"acceptance", j}};
  const std::string page = fleet::fleet_html(charts, "all", station::report::Assets{});
  EXPECT_NE(page.find("not computed: scale factor, room: 3 of 4 points not measured"),
            std::string::npos);
  EXPECT_NE(page.find("data-figure=\"acceptance-K-1\""), std::string::npos);
}

// The reasons from hand-made objects (pure): one ladder gives K but no TC; none gives neither.
TEST(FleetAcceptanceReasons, OneLadderGivesKButNoTemperatureCoefficientAndNoLadderNeither) {
  const json one = json::parse(R"({"serial": "A", "ladders": [{"label": "room", "ok": true,
      "temp_c": 24.5, "sf_pulse_per_arcsec": 0.6667, "sf_se_pulse_per_arcsec": 2e-6}]})");
  EXPECT_EQ(fleet::scale_factor_missing(one), "");
  EXPECT_EQ(fleet::temperature_coefficient_missing(one),
            "1 ladder computed: a temperature coefficient needs two plateaus");
  const json none = json::parse(R"({"serial": "A", "ladders": [], "positions": []})");
  EXPECT_EQ(fleet::scale_factor_missing(none), "no rate_ladder step in the run");
  EXPECT_EQ(fleet::temperature_coefficient_missing(none), "no rate_ladder step in the run");
  const json close = json::parse(R"({"serial": "A", "ladders": [{"label": "a", "ok": true,
      "temp_c": 25, "sf_pulse_per_arcsec": 0.6667, "sf_se_pulse_per_arcsec": 2e-6}],
      "sf_vs_temp": {"ok": false, "error": "plateaus under 1 C apart"}})");
  EXPECT_EQ(fleet::temperature_coefficient_missing(close), "plateaus under 1 C apart");
  EXPECT_EQ(fleet::scale_factor_missing(json("garbage")), "the stored figures are not readable");
}

}  // namespace
