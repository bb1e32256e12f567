// Test helper: a throw-away PostgreSQL per test process with the fleet schema, simulated
// station databases, and row-by-row comparison of what a station holds with what the server got.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "station/fleet/fleet_merge.hpp"
#include "station/fleet/fleet_schema.hpp"
#include "station/fleet/forwarder.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/sqlite.hpp"
#include "tests/fleet/pg_server.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"

namespace station::testing_support {

class FleetTest : public ::testing::Test {
 public:
  /// The test's own central database (a fresh one per test, on the process's server).
  static fleet::PgTarget target() { return {server_->url(db_), {}}; }

 protected:
  static void SetUpTestSuite() {
    skip_ = ThrowawayPostgres::unavailable();
    if (skip_.empty()) server_ = std::make_unique<ThrowawayPostgres>();
  }
  static void TearDownTestSuite() { server_.reset(); }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    db_ = "fleet_" + std::to_string(++tests_);
    server_->create_db(db_);
    fleet::PgConnection pg(target());
    fleet::init_fleet_schema(pg);
  }
  /// A finished simulated run of `gyros` gyros (tests/data/short_cycle.toml, about 2.2 h of
  /// simulated time) with its fits, in a fresh database; returns the path.
  static std::string simulated_station(const std::string& name, int gyros, std::uint64_t seed) {
    const auto db = fresh_db(name);
    auto o = short_cycle_run(db, gyros);
    o.seed = seed;
    station::run_simulated(o);
    return db;
  }

  /// Forwards until nothing is pending; returns the totals.
  static fleet::PassResult forward_all(const std::string& db, bool samples,
                                       std::int64_t batch_rows = 50'000) {
    fleet::ForwardOptions o;
    o.samples = samples;
    o.batch_rows = batch_rows;
    o.station = "test";
    fleet::Forwarder f(db, target(), o);
    fleet::PassResult total;
    for (int i = 0; i < 10'000; ++i) {
      const auto p = f.pass();
      total += p;
      if (!p.more) break;
    }
    return total;
  }

  static inline std::unique_ptr<ThrowawayPostgres> server_;
  static inline std::string skip_;
  static inline std::string db_ = "postgres";
  static inline int tests_ = 0;
};

/// One value as both sides can be compared: numbers by their double value (the shortest text
/// that reads back to it), uuids without dashes (SQLite keeps 32 hex digits), text as is.
inline std::string normalized(const std::string& v) {
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (!v.empty() && end == v.c_str() + v.size()) return fmt::format("{}", d);
  if (v.size() == 36 && v[8] == '-' && v[13] == '-' && v[18] == '-' && v[23] == '-') {
    std::string hex = v;
    hex.erase(std::remove(hex.begin(), hex.end(), '-'), hex.end());
    return hex;
  }
  return v;
}

/// COPY-text rows (fleet::encode_rows) as sorted rows of normalized fields.
inline std::vector<std::string> normalized_rows(const std::string& copy_text) {
  std::vector<std::string> rows;
  std::size_t start = 0;
  while (start < copy_text.size()) {
    const auto nl = copy_text.find('\n', start);
    const std::string line = copy_text.substr(start, nl - start);
    start = nl + 1;
    std::string row;
    std::size_t f = 0;
    for (;;) {
      const auto tab = line.find('\t', f);
      row += normalized(line.substr(f, tab - f)) + "|";
      if (tab == std::string::npos) break;
      f = tab + 1;
    }
    rows.push_back(row);
  }
  std::sort(rows.begin(), rows.end());
  return rows;
}

/// The ids of `sql`'s first column.
inline std::vector<std::int64_t> ids(Database& db, const std::string& sql) {
  std::vector<std::int64_t> out;
  auto st = db.prepare(sql);
  while (st.step()) out.push_back(st.column_int(0));
  return out;
}

inline void bind_if(Statement& st, const char* name, auto v) {
  if (int i = st.parameter_index(name); i > 0) st.bind(i, v);
}

/// Every row the station holds for central table `t`, through the table's own SELECT.
inline std::vector<std::string> station_rows(const std::string& path, const fleet::FleetTable& t) {
  Database db(path, OpenMode::read_only);
  std::string text;
  const char* items[] = {"SELECT id FROM runs", "SELECT id FROM fits", "SELECT id FROM releases",
                         "SELECT id FROM verifications"};
  for (std::int64_t id : ids(db, items[static_cast<int>(t.item)])) {
    std::vector<std::string> serials = {""};
    if (t.name == "samples") {
      serials.clear();
      auto s = db.prepare("SELECT serial FROM run_slots WHERE run_id = ?");
      s.bind(1, id);
      while (s.step()) serials.push_back(s.column_text(0));
    }
    for (const auto& serial : serials) {
      auto st = db.prepare(t.select);
      bind_if(st, ":id", id);
      bind_if(st, ":after", -1e300);
      bind_if(st, ":limit", std::int64_t{-1});
      bind_if(st, ":serial", std::string_view(serial));
      bind_if(st, ":station", std::string_view("test"));
      text += fleet::encode_rows(st).data;
    }
  }
  return normalized_rows(text);
}

/// Every row the server holds in `t` (those `where` selects, when given).
inline std::vector<std::string> server_rows(const fleet::FleetTable& t,
                                            const std::string& where = "") {
  fleet::PgConnection pg(FleetTest::target());
  auto r = pg.exec(fmt::format("SELECT {} FROM {} {}", t.columns, t.name, where));
  std::string text;
  for (int i = 0; i < r.rows(); ++i) {
    for (int c = 0; c < r.columns(); ++c) {
      if (c > 0) text += '\t';
      const auto v = r.opt_text(i, c);
      fleet::append_copy_field(text, v ? std::optional<std::string_view>(*v) : std::nullopt);
    }
    text += '\n';
  }
  return normalized_rows(text);
}

}  // namespace station::testing_support
