// What a fit reads from the store (issue 37's `fit --all`): migration 14's index on the serial of
// run_slots, added to a version-13 database, and the bins' data and span read together.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "schemas/migrations.hpp"
#include "station/store/fit_bins.hpp"
#include "tests/station/synthetic_bins.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::testing_support::fresh_db;

// The plan SQLite chooses for `sql`, its lines joined.
std::string query_plan(station::Store& s, const std::string& sql) {
  auto st = s.db().prepare("EXPLAIN QUERY PLAN " + sql);
  std::string out;
  while (st.step()) out += st.column_text(3) + "\n";
  return out;
}

// Bins of one serial with distinct ranges each: bin i spans temp [i - 1, i + 2], gradient
// [-0.1 i, 0.1 i].
std::vector<station::compensation::Bin> ranged_bins(int n, double offset) {
  station::testing_support::SyntheticGyro g;
  auto bins = station::testing_support::synthetic_bins(g, n);
  for (int i = 0; i < n; ++i) {
    auto& b = bins[static_cast<std::size_t>(i)];
    b.temp_min_c = offset + i - 1, b.temp_max_c = offset + i + 2;
    b.grad_min_c = -0.1 * i, b.grad_max_c = 0.1 * i;
  }
  return bins;
}

}  // namespace

// A version-13 database (the one before the index) with two runs of serial A: the next writer
// adds the index, keeps the slots, and the serial's runs are found through it, in run order.
TEST(FitReads, MigrationFourteenIndexesRunSlotsByTheSerialOfAVersion13Database) {
  const auto path = fresh_db("fit_reads_v13");
  {
    station::Database db(path);
    for (std::size_t i = 0; i < 13; ++i) db.exec(station::schemas::kMigrations[i].second);
    db.exec("PRAGMA user_version = 13");
    db.exec("INSERT INTO gyros (serial, first_seen_utc) VALUES ('A', 'x'), ('B', 'x');");
    for (int run : {2, 1, 3}) {
      db.exec(
          "INSERT INTO runs (id, started_utc, state, protocol_name, protocol_text, "
          "config_text, software_version, station) VALUES (" +
          std::to_string(run) + ", 'x', 'completed', 'p', '', '', '0.1', 'rig');");
    }
    db.exec(
        "INSERT INTO run_slots (run_id, slot, node, serial, pulse_weight_arcsec, axis, "
        "earth_rate_dph) VALUES (2, 0, 1, 'A', 1.5, 'up', 0), (1, 0, 1, 'B', 1.5, 'up', 0), "
        "(3, 1, 2, 'A', 1.5, 'up', 0), (3, 0, 1, 'B', 1.5, 'up', 0);");
  }
  station::Store s(path);
  ASSERT_GE(s.db().schema_version(), 14);
  EXPECT_EQ(s.runs_of_serial("A"), (std::vector<std::int64_t>{2, 3}));
  EXPECT_EQ(s.runs_of_serial("B"), (std::vector<std::int64_t>{1, 3}));
  EXPECT_TRUE(s.runs_of_serial("C").empty());
  // Read from the index alone, in its order: no scan of the table, no sort.
  const std::string plan =
      query_plan(s, "SELECT DISTINCT run_id FROM run_slots WHERE serial = 'A' ORDER BY run_id");
  EXPECT_NE(plan.find("COVERING INDEX run_slots_by_serial"), std::string::npos) << plan;
  EXPECT_EQ(plan.find("TEMP B-TREE"), std::string::npos) << plan;
}

// fit_bins gives model_data's rows and the span SQLite's own min and max give over the same
// complete bins of the runs asked; an incomplete bin counts in neither.
TEST(FitReads, FitBinsGivesTheModelDataAndTheSpanOfTheSameBins) {
  station::Store s(fresh_db("fit_reads_span"));
  const station::RunInfo info{"synthetic", "", "", "test", "bench", "", std::nullopt, 0.0, {}};
  const auto r1 = s.create_run(info, {{0, 1, "A", "up", 1.5, 0.0, ""}});
  const auto r2 = s.create_run(info, {{0, 1, "A", "up", 1.5, 0.0, ""}});
  auto b1 = ranged_bins(10, 0.0), b2 = ranged_bins(12, 30.0);
  b2.back().complete = false;  // its range (up to 43 C) must not count
  s.replace_bins(r1, "A", b1, 0.0);
  s.replace_bins(r2, "A", b2, 0.0);
  const auto got = station::fit_bins(s, "A", {r1, r2});
  const auto data = s.model_data("A", {r1, r2});
  EXPECT_EQ(got.data.bias_dph, data.bias_dph);
  EXPECT_EQ(got.data.temp_c, data.temp_c);
  EXPECT_EQ(got.data.segment, data.segment);
  EXPECT_EQ(got.data.t_mid_s, data.t_mid_s);
  ASSERT_EQ(got.data.bias_dph.size(), 21u);
  auto agg = s.db().prepare(
      "SELECT min(temp_min_c), max(temp_max_c), min(grad_min_c), max(grad_max_c) FROM bins "
      "WHERE serial = 'A' AND complete = 1");
  ASSERT_TRUE(agg.step());
  const station::FitSpan want{agg.column_double(0), agg.column_double(1), agg.column_double(2),
                              agg.column_double(3)};
  ASSERT_TRUE(got.span.has_value());
  EXPECT_EQ(*got.span, want);
  EXPECT_EQ(*got.span, (station::FitSpan{-1.0, 30.0 + 10 + 2, -1.0, 1.0}));
  // One run: its own span.
  EXPECT_EQ(*station::fit_bins(s, "A", {r1}).span, (station::FitSpan{-1.0, 11.0, -0.9, 0.9}));
}

// A complete bin stored before migration 8 (its ranges NULL) leaves the span empty, whichever
// run it is in, as the fit's span is then unknown; no bin at all: empty as well.
TEST(FitReads, ABinWithoutItsRangesLeavesTheSpanEmpty) {
  station::Store s(fresh_db("fit_reads_null"));
  const station::RunInfo info{"synthetic", "", "", "test", "bench", "", std::nullopt, 0.0, {}};
  const auto r1 = s.create_run(info, {{0, 1, "A", "up", 1.5, 0.0, ""}});
  const auto r2 = s.create_run(info, {{0, 1, "A", "up", 1.5, 0.0, ""}});
  s.replace_bins(r1, "A", ranged_bins(5, 0.0), 0.0);
  s.replace_bins(r2, "A", ranged_bins(5, 0.0), 0.0);
  EXPECT_TRUE(station::fit_bins(s, "A", {r1, r2}).span.has_value());
  s.db().exec("UPDATE bins SET grad_max_c = NULL WHERE run_id = " + std::to_string(r1) +
              " AND t_start_s = 1200");
  const auto got = station::fit_bins(s, "A", {r1, r2});
  EXPECT_FALSE(got.span.has_value());
  EXPECT_EQ(got.data.bias_dph.size(), 10u);  // the data are all there
  EXPECT_FALSE(station::fit_bins(s, "A", {r2, r1}).span.has_value());
  EXPECT_TRUE(station::fit_bins(s, "A", {r2}).span.has_value());
  EXPECT_FALSE(station::fit_bins(s, "B", {r1}).span.has_value());
}
