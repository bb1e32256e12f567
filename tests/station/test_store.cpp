// Store: migrations, WAL, tick transactions, fits round trip, rollback on failure.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "station/store/store.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::testing_support::fresh_db;

station::RunInfo info() {
  return {"paper", "[[step]]", "[station]", "0.1.0", "rig", "alice", 42};
}

}  // namespace

TEST(Store, MigratesToTheLatestVersionInWalMode) {
  const auto path = fresh_db("migrate");
  station::Store s(path);
  EXPECT_EQ(s.db().schema_version(), 3);
  auto st = s.db().prepare("PRAGMA journal_mode");
  ASSERT_TRUE(st.step());
  EXPECT_EQ(st.column_text(0), "wal");
  // Reopening does not re-apply anything.
  station::Store again(path);
  EXPECT_EQ(again.db().schema_version(), 3);
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
    station::RunProgress p{2, 1.0, static_cast<double>(t), t >= 2, 2.0, std::nullopt};
    s.append_tick(run, {r}, p);
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
  EXPECT_DOUBLE_EQ(unfinished->progress.t_s, 4.0);
  EXPECT_EQ(unfinished->sim_seed, 42);
  s.finish_run(run, "completed");
  EXPECT_FALSE(s.find_unfinished_run().has_value());
  EXPECT_EQ(s.run_slots(run).at(0).serial, "SN1");
}

TEST(Store, FailedTickRollsBackWhole) {
  const auto path = fresh_db("rollback");
  station::Store s(path);
  const auto run = s.create_run(info(), {});
  station::SampleRow ok;
  ok.serial = "A";
  s.append_tick(run, {ok}, {});
  // A row for a run that does not exist violates the foreign key: the whole tick is undone.
  station::SampleRow second = ok;
  second.t_s = 1;
  EXPECT_THROW(s.append_tick(run + 100, {second}, {}), station::SqliteError);
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
