// Issue 24: store and forward to a real PostgreSQL 15 (a throw-away server per test process).
// Every row of a simulated run arrives and equals the SQLite row; a resend after lost
// acknowledgements changes nothing; two stations forwarding at once keep their runs apart.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>

#include "station/store/store.hpp"
#include "tests/fleet/fleet_fixture.hpp"

namespace {

using station::Database;
using station::OpenMode;
using station::Statement;
namespace fleet = station::fleet;
using station::testing_support::FleetTest;
using station::testing_support::normalized_rows;
using station::testing_support::server_rows;
using station::testing_support::station_rows;

std::int64_t count(const std::string& table) {
  fleet::PgConnection pg(FleetTest::target());
  return pg.exec("SELECT count(*) FROM " + table).integer(0, 0);
}

class FleetForward : public FleetTest {};

TEST_F(FleetForward, EveryRowArrivesAndEqualsTheSqliteRow) {
  const auto db = simulated_station("fleet_every_row", 2, 7);
  const auto sent = forward_all(db, true, 5'000);  // several batches per run
  EXPECT_EQ(sent.failed, 0) << sent.last_error;
  for (const auto& t : fleet::fleet_tables()) {
    const auto local = station_rows(db, t), central = server_rows(t);
    // A run of the thermal cycle has no acceptance step (test_fleet_acceptance.cpp has one).
    if (t.name != "releases" && t.name != "verifications" && t.name != "acceptance_results" &&
        t.name != "acceptance_turn_on_steps") {
      EXPECT_GT(local.size(), 0u) << t.name << ": the simulated run should have rows";
    }
    EXPECT_EQ(local, central) << t.name;
  }
  fleet::Forwarder f(db, target(), {.samples = true, .batch_rows = 50'000, .station = "test"});
  const auto left = f.backlog();
  EXPECT_EQ(left.items, 0);
  EXPECT_EQ(left.rows, 0);
}

TEST_F(FleetForward, ResendAfterLostAcknowledgementsChangesNothing) {
  const auto db = simulated_station("fleet_resend", 1, 3);
  forward_all(db, true);
  fleet::PgConnection pg(target());
  const auto xmin_before = pg.exec("SELECT string_agg(xmin::text, ',' ORDER BY uuid) FROM runs");
  const auto fits_before = pg.exec("SELECT string_agg(xmin::text, ',' ORDER BY uuid) FROM fits");
  const std::int64_t samples = count("samples"), events = count("events"), bins = count("bins");
  {
    // As after a restored backup or acknowledgements lost to a kill: everything pending again.
    Database w(db, OpenMode::existing);
    w.exec("UPDATE fleet_outbox SET acked = 0, events_acked_id = NULL, samples_acked_t_s = NULL");
  }
  const auto again = forward_all(db, true);
  EXPECT_EQ(again.failed, 0) << again.last_error;
  EXPECT_EQ(again.rows, 0) << "a resend wrote rows";
  EXPECT_EQ(again.appended, 0) << "events or samples were sent twice";
  EXPECT_EQ(count("samples"), samples);
  EXPECT_EQ(count("events"), events);
  EXPECT_EQ(count("bins"), bins);
  // Not rewritten either: a row's xmin changes with every UPDATE (PostgreSQL MVCC).
  EXPECT_EQ(pg.exec("SELECT string_agg(xmin::text, ',' ORDER BY uuid) FROM runs").text(0, 0),
            xmin_before.text(0, 0));
  EXPECT_EQ(pg.exec("SELECT string_agg(xmin::text, ',' ORDER BY uuid) FROM fits").text(0, 0),
            fits_before.text(0, 0));
}

TEST_F(FleetForward, LocalChangesAfterForwardingArrive) {
  const auto db = simulated_station("fleet_change", 1, 4);
  forward_all(db, false);
  EXPECT_EQ(count("samples"), 0) << "samples travel only when asked for";
  {
    Database w(db, OpenMode::existing);
    w.exec("UPDATE fits SET part_number = 'RLG-90' WHERE id = (SELECT max(id) FROM fits)");
    w.exec(
        "DELETE FROM bins WHERE (run_id, serial, t_start_s) IN (SELECT run_id, serial, t_start_s "
        "FROM bins LIMIT 1)");
  }
  const auto again = forward_all(db, false);
  EXPECT_EQ(again.failed, 0) << again.last_error;
  EXPECT_GE(again.rows, 2);  // the fit updated, the bin gone
  EXPECT_EQ(station_rows(db, fleet::fleet_table("fits")), server_rows(fleet::fleet_table("fits")));
  EXPECT_EQ(station_rows(db, fleet::fleet_table("bins")), server_rows(fleet::fleet_table("bins")));
}

TEST_F(FleetForward, TwoStationsAtOnceKeepTheirRunsApart) {
  const auto a = simulated_station("fleet_station_a", 2, 11);
  const auto b = simulated_station("fleet_station_b", 2, 12);
  for (const auto& [db, name] : {std::pair{a, "rig-a"}, std::pair{b, "rig-b"}}) {
    Database w(db, OpenMode::existing);
    w.exec(fmt::format("UPDATE runs SET station = '{}'", name));
  }
  fleet::PassResult ra, rb;
  std::thread ta([&] { ra = forward_all(a, true, 3'000); });
  std::thread tb([&] { rb = forward_all(b, true, 3'000); });
  ta.join();
  tb.join();
  EXPECT_EQ(ra.failed + rb.failed, 0) << ra.last_error << rb.last_error;
  for (const auto& [db, name] : {std::pair{a, "rig-a"}, std::pair{b, "rig-b"}}) {
    Database r(db, OpenMode::read_only);
    auto u = r.prepare("SELECT uuid FROM runs");
    ASSERT_TRUE(u.step());
    const std::string where = fmt::format("WHERE run_uuid = '{}'", u.column_text(0));
    for (const char* t : {"samples", "events", "bins", "run_slots"})
      EXPECT_EQ(station_rows(db, fleet::fleet_table(t)), server_rows(fleet::fleet_table(t), where))
          << name << " " << t;
    EXPECT_EQ(server_rows(fleet::fleet_table("runs"), fmt::format("WHERE station = '{}'", name)),
              station_rows(db, fleet::fleet_table("runs")));
  }
}

std::string xmins(fleet::PgConnection& pg, const std::string& table) {
  return pg.exec("SELECT coalesce(string_agg(xmin::text, ',' ORDER BY uuid), '') FROM " + table)
      .text(0, 0);
}

// The station's disk is lost after it forwarded changes made since its last backup; the backup
// is restored and records something new. The restored file's run and fit are behind the server
// (their revision is lower): held, nothing of them written; the server keeps what it had.
TEST_F(FleetForward, ARestoredBackupIsHeldAndWritesNothingOverTheServer) {
  const auto db = simulated_station("fleet_restore", 1, 31);
  const auto backup = db + ".backup";
  std::remove(backup.c_str());
  {
    Database w(db, OpenMode::existing);
    w.exec("VACUUM INTO '" + backup + "'");
    w.exec("UPDATE fits SET part_number = 'RLG-90'");
    w.exec(
        "INSERT INTO events (run_id, t_s, wall_utc, severity, source, kind, message) SELECT "
        "max(id), 9000, '2026-11-26T00:00:00Z', 'info', 'test', 'note', 'after the backup' FROM "
        "runs");
  }
  forward_all(db, false);
  fleet::PgConnection pg(target());
  const auto runs = xmins(pg, "runs"), fits = xmins(pg, "fits");
  const std::int64_t events = count("events");
  {
    Database w(backup, OpenMode::existing);
    w.exec(
        "INSERT INTO events (run_id, t_s, wall_utc, severity, source, kind, message) SELECT "
        "max(id), 9000, '2026-11-26T01:00:00Z', 'info', 'test', 'note', 'after the restore' FROM "
        "runs");
  }
  const auto restored = forward_all(backup, false);
  EXPECT_EQ(restored.failed, 2) << restored.last_error;  // the run and its fit
  EXPECT_NE(restored.last_error.find("restored from a backup"), std::string::npos)
      << restored.last_error;
  EXPECT_EQ(restored.rows, 0);
  EXPECT_EQ(xmins(pg, "runs"), runs);
  EXPECT_EQ(xmins(pg, "fits"), fits);
  EXPECT_EQ(count("events"), events);
  fleet::Forwarder f(backup, target(), {});
  EXPECT_EQ(f.backlog().held, 2);
  EXPECT_EQ(f.pass().failed, 0) << "a held item is not tried again by itself";
  std::remove(backup.c_str());
}

// Issue 34 point 7b: an event edited on the server. The run is held as before (the server and
// the file have parted) and the error says which row and which column.
TEST_F(FleetForward, AnEditedCentralEventIsNamedByItsKeyAndColumn) {
  const auto db = simulated_station("fleet_edited_event", 1, 34);
  forward_all(db, false);
  fleet::PgConnection pg(target());
  const auto edited = pg.exec(
      "UPDATE events SET message = 'edited' WHERE local_id = (SELECT max(local_id) FROM "
      "events) RETURNING run_uuid, local_id");
  ASSERT_EQ(edited.rows(), 1);
  {
    Database w(db, OpenMode::existing);
    w.exec(
        "INSERT INTO events (run_id, t_s, wall_utc, severity, source, kind, message) SELECT "
        "max(id), 9000, '2026-11-26T00:00:00Z', 'info', 'test', 'note', 'later' FROM runs");
  }
  const auto again = forward_all(db, false);
  EXPECT_EQ(again.failed, 1) << again.last_error;
  const std::string want = fmt::format(
      "the server's events row (run_uuid={}, local_id={}) "
      "differs from this file's in message",
      edited.text(0, 0), edited.text(0, 1));
  EXPECT_NE(again.last_error.find(want), std::string::npos) << again.last_error;
}

// Issue 34 point 7c: two station files under one [station] name. The first binds the name to its
// identity; the second is refused naming both identities, and nothing of it reaches the server.
TEST_F(FleetForward, ASecondStationUnderAHeldNameIsRefusedNamingBoth) {
  const auto a = simulated_station("fleet_name_a", 1, 35);
  const auto b = simulated_station("fleet_name_b", 1, 36);
  std::vector<std::string> identities;
  for (const auto& db : {a, b}) {
    Database w(db, OpenMode::existing);
    w.exec("UPDATE runs SET station = 'rig-x'");
    auto id = w.prepare("SELECT uuid FROM station_identity");
    ASSERT_TRUE(id.step());
    identities.push_back(id.column_text(0));
  }
  ASSERT_NE(identities[0], identities[1]);
  EXPECT_EQ(forward_all(a, false).failed, 0);
  const std::int64_t runs = count("runs"), fits = count("fits"), events = count("events");
  const auto second = forward_all(b, false);
  EXPECT_GT(second.failed, 0);
  const std::string& said = second.last_error;
  EXPECT_NE(said.find("station name 'rig-x' is held"), std::string::npos) << said;
  for (const auto& hex : identities) {  // as PostgreSQL writes a uuid: 8-4-4-4-12
    const std::string uuid = fmt::format("{}-{}-{}-{}-{}", hex.substr(0, 8), hex.substr(8, 4),
                                         hex.substr(12, 4), hex.substr(16, 4), hex.substr(20));
    EXPECT_NE(said.find(uuid), std::string::npos) << said;
  }
  EXPECT_EQ(count("runs"), runs);
  EXPECT_EQ(count("fits"), fits);
  EXPECT_EQ(count("events"), events);
  EXPECT_EQ(forward_all(a, false).failed, 0) << "the holder goes on";
}

// Samples not wanted at first (a pass without them acknowledges the run), wanted later: they go.
TEST_F(FleetForward, SamplesWantedLaterAreSentForRunsAlreadyAcknowledged) {
  const auto db = simulated_station("fleet_samples_later", 1, 32);
  forward_all(db, false);
  EXPECT_EQ(count("samples"), 0);
  fleet::Forwarder f(db, target(), {.samples = true, .batch_rows = 50'000, .station = "test"});
  EXPECT_GT(f.backlog().rows, 1000) << "the samples are pending once wanted";
  const auto later = forward_all(db, true);
  EXPECT_EQ(station_rows(db, fleet::fleet_table("samples")),
            server_rows(fleet::fleet_table("samples")));
  EXPECT_GT(later.appended, 1000);
  EXPECT_EQ(forward_all(db, true).appended, 0) << "then nothing is pending";
}

// An item the server refuses waits its back-off (0.5 s doubling): the pass goes on with the
// others, does not spin on it, and it arrives once the server takes it.
TEST_F(FleetForward, ARefusedItemWaitsItsTurnAndTheOthersGoOn) {
  const auto db = simulated_station("fleet_refused", 2, 33);
  fleet::PgConnection pg(target());
  pg.exec("ALTER TABLE fits ADD CONSTRAINT refuse_one CHECK (serial <> 'SIM-0001')");
  const auto first = forward_all(db, false);
  EXPECT_EQ(first.failed, 1) << first.last_error;
  EXPECT_NE(first.last_error.find("refuse_one"), std::string::npos) << first.last_error;
  EXPECT_EQ(count("fits"), 1);
  EXPECT_EQ(count("runs"), 1);
  fleet::Forwarder f(db, target(), {});
  const auto again = f.pass();
  EXPECT_EQ(again.items + again.failed, 0) << "retried before its back-off";
  pg.exec("ALTER TABLE fits DROP CONSTRAINT refuse_one");
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  const auto later = f.pass();
  EXPECT_EQ(later.items, 1);
  EXPECT_EQ(count("fits"), 2);
}

// Issue 37: a COPY streamed piece by piece while its rows are made (how samples travel). Rows of
// many pieces arrive whole; rows that cannot be made (the fill throws) fail the COPY with nothing
// written; a row the server refuses mid-stream (a duplicate key) is the COPY's error; after either
// the connection goes on.
TEST_F(FleetForward, AStreamedCopyArrivesWholeOrNotAtAll) {
  fleet::PgConnection pg(target());
  pg.exec("CREATE TABLE streamed (k bigint PRIMARY KEY, note text)");
  const auto rows = [](std::int64_t first, std::int64_t n, std::int64_t fail_at) {
    return [=, k = first](std::string& piece) mutable {
      for (; k < first + n && piece.size() < fleet::kPgCopyPieceBytes; ++k) {
        if (k == fail_at) throw std::runtime_error("row cannot be read");
        fmt::format_to(std::back_inserter(piece), "{}\tnote {}\n", k, k);
      }
      return k < first + n;
    };
  };
  constexpr std::int64_t kRows = 20'000;  // ~330 kB: six pieces
  const auto sum_sql = "SELECT count(*), sum(k) FROM streamed";
  EXPECT_EQ(pg.copy_in("streamed (k, note)", rows(0, kRows, -1)), kRows);
  EXPECT_EQ(pg.exec(sum_sql).integer(0, 0), kRows);
  EXPECT_EQ(pg.exec(sum_sql).integer(0, 1), kRows * (kRows - 1) / 2);
  EXPECT_THROW(pg.copy_in("streamed (k, note)", rows(kRows, kRows, kRows + 15'000)),
               std::runtime_error);
  EXPECT_TRUE(pg.ok());
  EXPECT_EQ(pg.exec(sum_sql).integer(0, 0), kRows) << "a failed COPY wrote rows";
  std::string refused;
  try {
    pg.copy_in("streamed (k, note)", rows(kRows - 1, kRows, -1));
  } catch (const fleet::PgError& e) {
    refused = e.what();
  }
  EXPECT_NE(refused.find("duplicate key"), std::string::npos) << refused;
  EXPECT_TRUE(pg.ok());
  EXPECT_EQ(pg.exec(sum_sql).integer(0, 0), kRows);
}

}  // namespace
