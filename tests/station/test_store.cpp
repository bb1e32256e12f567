// Store: migrations, WAL, tick transactions, fits round trip, rollback on failure.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "schemas/migrations.hpp"
#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::testing_support::fresh_db;

// Every file beside `db` whose name starts with its name and ".schema-v" (copies and .tmp).
std::vector<std::filesystem::path> copies_of(const std::string& db) {
  const std::filesystem::path p(db);
  std::vector<std::filesystem::path> out;
  for (const auto& e : std::filesystem::directory_iterator(p.parent_path())) {
    const auto name = e.path().filename().string();
    if (name.rfind(p.filename().string() + ".schema-v", 0) == 0) out.push_back(e.path());
  }
  return out;
}

// A version-1 database with run 1 'running' and `samples` samples of serial A at t = 41, 42, ...
void make_v1_db(const std::string& path, int samples) {
  station::Database db(path);
  db.exec(station::schemas::kMigrations[0].second);
  db.exec("PRAGMA user_version = 1");
  db.exec(
      "INSERT INTO runs (id, started_utc, state, protocol_name, protocol_text, config_text, "
      "software_version, station) VALUES (1, 'x', 'running', 'p', '', '', '0.1', 'rig');");
  db.exec("WITH RECURSIVE c(x) AS (SELECT 41 UNION ALL SELECT x + 1 FROM c WHERE x < " +
          std::to_string(40 + samples) +
          ") INSERT INTO samples (run_id, serial, t_s, flags, recording) "
          "SELECT 1, 'A', x, 0, 0 FROM c;");
}

station::RunInfo info() {
  return {"paper", "[[step]]", "[station]", "0.1.0", "rig", "alice", 42, 0.0, {}};
}

}  // namespace

TEST(Store, MigratesToTheLatestVersionInWalMode) {
  const auto path = fresh_db("migrate");
  station::Store s(path);
  const int latest = static_cast<int>(station::schemas::kMigrations.size());
  EXPECT_GE(latest, 4);  // 4: honest and OLS standard errors of fits
  EXPECT_EQ(s.db().schema_version(), latest);
  auto st = s.db().prepare("PRAGMA journal_mode");
  ASSERT_TRUE(st.step());
  EXPECT_EQ(st.column_text(0), "wal");
  // Reopening does not re-apply anything.
  station::Store again(path);
  EXPECT_EQ(again.db().schema_version(), latest);
}

TEST(Store, RefusesADatabaseNewerThanTheSoftware) {
  const auto path = fresh_db("newer");
  {
    station::Database db(path);
    db.exec("PRAGMA user_version = 99");
  }
  EXPECT_THROW(station::Store{path}, station::SqliteError);
}

TEST(Store, TicksAndProgressRoundTrip) {
  const auto path = fresh_db("ticks");
  station::Store s(path);
  const auto run = s.create_run(info(), {{0, 1, "SN1", "up", 1.5, 9.6}});
  for (int t = 0; t < 5; ++t) {
    station::SampleRow r;
    r.serial = "SN1";
    r.t_s = t;
    r.net_pulses = 7 + t;
    r.rate_dph = 10.5 + t;
    r.temp_c = 20.0;
    r.recording = t >= 2;
    station::RunProgress p{2, 1.0, t >= 2, 2.0, std::nullopt};
    s.append_tick(run, t, {r}, p);
  }
  EXPECT_EQ(s.sample_count(run), 5);
  const auto rec = s.samples(run, "SN1", true);
  ASSERT_EQ(rec.size(), 3u);
  EXPECT_EQ(*rec[0].net_pulses, 9);
  EXPECT_DOUBLE_EQ(*rec[2].rate_dph, 14.5);
  EXPECT_FALSE(rec[0].temp2_c.has_value());
  const auto unfinished = s.find_unfinished_run();
  ASSERT_TRUE(unfinished.has_value());
  EXPECT_EQ(unfinished->id, run);
  EXPECT_EQ(unfinished->progress.step_index, 2);
  ASSERT_TRUE(unfinished->last_tick_s.has_value());
  EXPECT_DOUBLE_EQ(*unfinished->last_tick_s, 4.0);
  EXPECT_EQ(unfinished->sim_seed, 42);
  s.finish_run(run, station::RunState::completed);
  EXPECT_FALSE(s.find_unfinished_run().has_value());
  EXPECT_EQ(s.run_slots(run).at(0).serial, "SN1");
}

TEST(Store, FailedTickRollsBackWhole) {
  const auto path = fresh_db("rollback");
  station::Store s(path);
  const auto run = s.create_run(info(), {});
  station::SampleRow ok;
  ok.serial = "A";
  s.append_tick(run, 0, {ok}, {});
  // A row for a run that does not exist violates the foreign key: the whole tick is undone.
  station::SampleRow second = ok;
  second.t_s = 1;
  EXPECT_THROW(s.append_tick(run + 100, 1, {second}, {}), station::SqliteError);
  EXPECT_EQ(s.sample_count(run), 1);
  EXPECT_EQ(s.sample_count(run + 100), 0);
}

TEST(Store, FitsRoundTrip) {
  const auto path = fresh_db("fits");
  station::Store s(path);
  namespace sc = station::compensation;
  sc::FitResult fit;
  fit.spec.terms = {sc::Term::dT, sc::Term::gradT};
  fit.names = {"B0", "k1", "k0"};
  fit.coefficients = {0.05, 1.2e-3, 0.012};
  fit.std_errors = {1e-3, 4e-5, 1e-4};
  fit.std_errors_ols = {7e-4, 3e-5, 6e-5};
  fit.error_model = {};
  fit.error_model.method = "ar1+white (REML)";
  fit.error_model.corr_time_s = 3400.0;
  fit.error_model.correlated_share = 0.2;
  fit.error_model.sigma_dph = 0.008;
  fit.error_model.rho_per_bin = 0.84;
  fit.n_points = 66;
  fit.r2 = 0.99;
  const sc::Evaluation ev{0.12, 0.007, 0.0583, 94.17};
  s.save_fit("SN9", {1, 2}, fit, ev);
  const auto got = s.latest_fit("SN9");
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->runs, (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(got->terms, "dT,gradT");
  EXPECT_DOUBLE_EQ(got->fit.coefficients[1], 1.2e-3);
  EXPECT_DOUBLE_EQ(got->fit.std_errors[2], 1e-4);
  EXPECT_EQ(got->fit.std_errors_ols, fit.std_errors_ols);
  EXPECT_EQ(got->fit.error_model.method, "ar1+white (REML)");
  EXPECT_DOUBLE_EQ(got->fit.error_model.corr_time_s, 3400.0);
  EXPECT_DOUBLE_EQ(got->fit.error_model.correlated_share, 0.2);
  EXPECT_DOUBLE_EQ(got->fit.error_model.sigma_dph, 0.008);
  ASSERT_TRUE(got->eval.std_ratio.has_value());
  EXPECT_DOUBLE_EQ(*got->eval.std_ratio, 0.0583);
  EXPECT_FALSE(s.latest_fit("nobody").has_value());
}

TEST(Store, BinsBecomeModelData) {
  const auto path = fresh_db("bins");
  station::Store s(path);
  const auto run = s.create_run(info(), {{0, 1, "SN1", "up", 1.5, 9.0}});
  std::vector<station::compensation::Bin> bins(3);
  for (int i = 0; i < 3; ++i) {
    bins[i].t_start_s = 600.0 * i;
    bins[i].rate_dph = 9.5 + i;
    bins[i].temp_c = 10.0 * i;
    bins[i].complete = i != 1;
  }
  s.replace_bins(run, "SN1", bins, 9.0);
  s.replace_bins(run, "SN1", bins, 9.0);  // idempotent
  const auto d = s.model_data("SN1", {run});
  ASSERT_EQ(d.bias_dph.size(), 2u);
  EXPECT_DOUBLE_EQ(d.bias_dph[0], 0.5);
  EXPECT_DOUBLE_EQ(d.bias_dph[1], 2.5);
  EXPECT_EQ(s.runs_of_serial("SN1"), std::vector<std::int64_t>{run});
}

TEST(Store, ANewRunHasNoLastTickUntilOneIsCommitted) {
  station::Store s(fresh_db("no-tick"));
  const auto run = s.create_run(info(), {{0, 1, "SN1", "up", 1.5, 9.6}});
  EXPECT_FALSE(s.find_run(run)->last_tick_s.has_value());
  station::SampleRow r;
  r.serial = "SN1";
  r.t_s = 0;
  s.append_tick(run, 0, {r}, {});
  EXPECT_DOUBLE_EQ(s.find_run(run)->last_tick_s.value(), 0.0);
}

TEST(Store, ACommittedSampleIsNeverReplaced) {
  // Issue 7.1: INSERT OR REPLACE turned "9.0|7|10.47" into "9.0|NULL|NULL" on a quick restart.
  const auto path = fresh_db("no-replace");
  station::Store s(path);
  const auto run = s.create_run(info(), {{0, 1, "SN1", "up", 1.5, 9.6}});
  station::SampleRow r;
  r.serial = "SN1";
  r.t_s = 9;
  r.net_pulses = 7;
  r.rate_dph = 10.47;
  s.append_tick(run, 9, {r}, {});
  station::SampleRow again;
  again.serial = "SN1";
  again.t_s = 9;  // same tick, nothing measured
  EXPECT_THROW(s.append_tick(run, 9, {again}, {}), station::SqliteError);
  const auto got = s.samples(run, "SN1", false);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].net_pulses, 7);
  EXPECT_DOUBLE_EQ(got[0].rate_dph.value(), 10.47);
}

TEST(Store, ReadOnlyAndExistingModesNeverCreateAFile) {
  const auto path = fresh_db("missing");
  EXPECT_THROW(station::Store(path, station::OpenMode::read_only), station::SqliteError);
  EXPECT_THROW(station::Store(path, station::OpenMode::existing), station::SqliteError);
  EXPECT_NE(access(path.c_str(), F_OK), 0) << "a read command created " << path;
}

TEST(Store, AnEmptyFileIsNotMigratedByAReadCommand) {
  const auto path = fresh_db("empty");
  { std::ofstream(path).flush(); }
  for (const auto mode : {station::OpenMode::read_only, station::OpenMode::existing}) {
    try {
      station::Store s(path, mode);
      ADD_FAILURE() << "an empty file was accepted";
    } catch (const station::SqliteError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("not a station database"), std::string::npos)
          << e.what();
    }
  }
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  EXPECT_EQ(in.tellg(), 0) << "the empty file was written to";
}

TEST(Store, ReadOnlyOpenServesReadsAndRefusesWrites) {
  const auto path = fresh_db("ro");
  std::int64_t run = 0;
  {
    station::Store s(path);
    run = s.create_run(info(), {{0, 1, "SN1", "up", 1.5, 9.6}});
  }
  station::Store ro(path, station::OpenMode::read_only);
  EXPECT_EQ(ro.run_slots(run).size(), 1u);
  EXPECT_THROW(ro.finish_run(run, station::RunState::completed), station::SqliteError);
}

namespace {

/// A station database with enough samples to span many pages, then page 3 overwritten.
std::string corrupt_db(const std::string& name) {
  const auto path = fresh_db(name);
  {
    station::Store s(path);
    const auto run = s.create_run(info(), {{0, 1, "SN1", "up", 1.5, 9.6}});
    s.set_ticks_per_commit(500);
    for (int t = 0; t < 2000; ++t) {
      station::SampleRow r;
      r.serial = "SN1";
      r.t_s = t;
      r.rate_dph = 10.0 + t;
      s.append_tick(run, t, {r}, {});
    }
    s.flush();
    s.db().exec("PRAGMA wal_checkpoint(TRUNCATE)");
  }
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary | std::ios::ate);
  const auto pages = static_cast<long>(f.tellg()) / 4096;
  f.seekp(4096 * (pages / 2));           // a page in the middle (4 KiB pages): samples b-tree data
  const std::string junk(2000, '\xA5');  // its page header and first cells
  f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
  return path;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(Store, ACorruptDatabaseIsRefusedInEveryModeAndNotWritten) {
  const auto path = corrupt_db("corrupt");
  const std::string before = file_bytes(path);
  for (const auto mode :
       {station::OpenMode::create, station::OpenMode::existing, station::OpenMode::read_only}) {
    try {
      station::Store s(path, mode);
      ADD_FAILURE() << "a corrupt database was accepted";
    } catch (const station::SqliteError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(file_bytes(path), before) << "the corrupt file was written to";
}

TEST(Store, AUserVersionOutsideTheKnownRangeIsRefused) {
  // Issue 7.6: a negative user_version indexed the migration table out of bounds.
  for (const int v : {-1, -2147483647, 99}) {
    const auto path = fresh_db("version" + std::to_string(v < 0 ? -v : v));
    {
      station::Database db(path);
      db.exec("PRAGMA user_version = " + std::to_string(v));
    }
    try {
      station::Store s(path);
      ADD_FAILURE() << "user_version " << v << " was accepted";
    } catch (const station::SqliteError& e) {
      EXPECT_NE(std::string(e.what()).find("schema version " + std::to_string(v)),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(Store, MigratesAVersion1DatabaseKeepingItsRunsAndLastTick) {
  const auto path = fresh_db("v1");
  make_v1_db(path, 1);
  station::Store s(path);
  const auto run = s.find_run(1);
  ASSERT_TRUE(run.has_value());
  EXPECT_EQ(run->state, station::RunState::running);
  EXPECT_DOUBLE_EQ(run->last_tick_s.value(), 41.0);
  EXPECT_EQ(run->resolved_json, "{}");
  s.finish_run(1, station::RunState::incomplete);  // allowed by version 2
  EXPECT_EQ(s.find_run(1)->state, station::RunState::incomplete);
  // The file as version 1 left it is kept beside it, whole and readable, with its run and
  // sample; no temporary is left.
  const auto copies = copies_of(path);
  ASSERT_EQ(copies.size(), 1U);
  EXPECT_EQ(copies[0].extension(), ".bak");
  station::Database copy(copies[0].string(), station::OpenMode::existing);
  EXPECT_EQ(copy.schema_version(), 1);
  auto st = copy.prepare("SELECT state, (SELECT COUNT(*) FROM samples) FROM runs WHERE id = 1");
  ASSERT_TRUE(st.step());
  EXPECT_EQ(st.column_text(0), "running");
  EXPECT_EQ(st.column_int(1), 1);
}

TEST(Store, DoesNotMigrateWhenTheCopyCannotBeWritten) {
  const auto path = fresh_db("v1-nocopy");
  make_v1_db(path, 20000);
  ASSERT_GT(std::filesystem::file_size(path), 256 * 1024U);
  // A full disk, as the process sees it: files may not grow past 128 KiB (EFBIG, no SIGXFSZ).
  rlimit was{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &was), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = was;
  small.rlim_cur = 128 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string error;
  try {
    station::Store s(path);
  } catch (const station::SqliteError& e) {
    error = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &was);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(error.find("not migrated from schema version 1: the copy"), std::string::npos) << error;
  EXPECT_TRUE(copies_of(path).empty()) << "a partial copy or its .tmp was left";
  station::Database db(path, station::OpenMode::existing);
  EXPECT_EQ(db.schema_version(), 1);
  // With room again, the next open copies and migrates.
  station::Store s(path);
  EXPECT_EQ(copies_of(path).size(), 1U);
}
