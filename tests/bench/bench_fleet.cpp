// Benchmarks of the fleet forwarder against a throw-away PostgreSQL 15 (tests/fleet/
// pg_server.hpp; skipped with a message without the server binaries):
//   BM_ForwardPaperRun8GyrosWithSamples  one 13 h run of 8 simulated gyros (the paper protocol:
//                                        ~375k samples, its bins, events and fits) from SQLite to
//                                        an empty server, samples included
//   BM_CatchUpRuns                       a backlog of short runs (no samples) after an outage:
//                                        runs per second
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>

#include "station/common/logging.hpp"
#include "station/fleet/fleet_schema.hpp"
#include "station/fleet/forwarder.hpp"
#include "station/sim/sim_run.hpp"
#include "tests/fleet/pg_server.hpp"

namespace {

using station::testing_support::ThrowawayPostgres;
namespace fleet = station::fleet;

ThrowawayPostgres* server() {
  static std::unique_ptr<ThrowawayPostgres> s =
      ThrowawayPostgres::unavailable().empty() ? std::make_unique<ThrowawayPostgres>() : nullptr;
  return s.get();
}

std::string simulated_db(const std::string& tag, const std::string& protocol, int gyros, int runs) {
  station::LogOptions lo;
  lo.console_level = spdlog::level::err;
  station::setup_logging(lo);
  const std::string db = "/tmp/station-bench-fleet-" + tag + std::to_string(getpid()) + ".db";
  for (const char* ext : {"", "-wal", "-shm"}) std::remove((db + ext).c_str());
  for (int r = 0; r < runs; ++r) {
    station::SimRunOptions o;
    o.gyros = gyros;
    o.db_path = db;
    o.progress = false;
    o.fresh = true;
    o.protocol = protocol;
    o.seed = static_cast<std::uint64_t>(r + 1);
    station::run_simulated(o);
  }
  return db;
}

// A fresh central database per iteration: every iteration forwards everything.
fleet::PgTarget fresh_target() {
  static int made = 0;
  const std::string name = "bench" + std::to_string(++made);
  server()->create_db(name);
  fleet::PgConnection pg({server()->url(name), {}});
  fleet::init_fleet_schema(pg);
  return {server()->url(name), {}};
}

fleet::PassResult forward_all(const std::string& db, const fleet::PgTarget& t, bool samples) {
  {
    station::Database w(db, station::OpenMode::existing);
    w.exec("UPDATE fleet_outbox SET acked = 0, events_acked_id = NULL, samples_acked_t_s = NULL");
  }
  fleet::Forwarder f(db, t, {samples, 50'000, "bench"});
  fleet::PassResult total;
  for (;;) {
    const auto p = f.pass();
    total += p;
    if (!p.more) break;
  }
  return total;
}

void run_forward(benchmark::State& state, const std::string& db, bool samples, int runs) {
  std::int64_t rows = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const auto t = fresh_target();
    state.ResumeTiming();
    rows = forward_all(db, t, samples).appended;
  }
  state.counters["rows_appended"] = static_cast<double>(rows);
  state.counters["runs_per_s"] =
      benchmark::Counter(runs, benchmark::Counter::kIsIterationInvariantRate);
  for (const char* ext : {"", "-wal", "-shm"}) std::remove((db + ext).c_str());
}

void BM_ForwardPaperRun8GyrosWithSamples(benchmark::State& state) {
  if (server() == nullptr) {
    state.SkipWithError(ThrowawayPostgres::unavailable().c_str());
    return;
  }
  run_forward(state, simulated_db("paper", "paper", 8, 1), true, 1);
}
BENCHMARK(BM_ForwardPaperRun8GyrosWithSamples)
    ->Iterations(2)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);

void BM_CatchUpRuns(benchmark::State& state) {
  if (server() == nullptr) {
    state.SkipWithError(ThrowawayPostgres::unavailable().c_str());
    return;
  }
  const int runs = static_cast<int>(state.range(0));
  run_forward(state, simulated_db("short", STATION_TEST_DATA_DIR "/short_cycle.toml", 4, runs),
              false, runs);
}
BENCHMARK(BM_CatchUpRuns)->Arg(20)->Iterations(3)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
