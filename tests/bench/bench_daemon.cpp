// Benchmark: the default 13 h protocol with 8 simulated gyros through the real stacks (Modbus TCP
// on loopback, CAN on a socketpair, SQLite WAL on disk), on the simulated clock. One iteration.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "station/common/logging.hpp"
#include "station/sim/sim_run.hpp"

namespace {

void BM_PaperProtocol8Gyros(benchmark::State& state) {
  station::LogOptions lo;
  lo.console_level = spdlog::level::err;
  station::setup_logging(lo);
  const std::string db = "/tmp/station-bench-" + std::to_string(getpid()) + ".db";
  double sim_s = 0;
  for (auto _ : state) {
    for (const char* ext : {"", "-wal", "-shm"}) std::remove((db + ext).c_str());
    station::SimRunOptions o;
    o.gyros = static_cast<int>(state.range(0));
    o.db_path = db;
    o.progress = false;
    o.fresh = true;
    const auto report = station::run_simulated(o);
    sim_s = report["sim_s"].get<double>();
  }
  state.counters["sim_h"] = sim_s / 3600.0;
  state.counters["ticks_per_s"] = benchmark::Counter(sim_s, benchmark::Counter::kIsRate);
  for (const char* ext : {"", "-wal", "-shm"}) std::remove((db + ext).c_str());
}
BENCHMARK(BM_PaperProtocol8Gyros)->Arg(8)->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);

}  // namespace
