// Benchmark: `station fit --all` over a database of 1,000 serials (63 runs of 16 slots, 66
// synthetic 600 s bins each, written through the Store API): every serial fitted over its run
// and the fits stored in one transaction, as fit_all does for the command.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "station/parts/judged_fit.hpp"
#include "station/store/serial_history.hpp"
#include "tests/station/synthetic_bins.hpp"

namespace {

namespace fs = std::filesystem;
using station::testing_support::SyntheticGyro;

// Removes the benchmark's database files when the program ends.
struct TempFiles {
  std::string base;
  ~TempFiles() {
    for (const char* f : {"", ".work.db", ".each.db"})
      for (const char* ext : {"", "-wal", "-shm"}) fs::remove(base + f + ext);
  }
};

// A database of `serials` gyros, 16 per run, built once per process.
const std::string& template_db(int serials) {
  static std::string path;
  static TempFiles cleanup;
  if (!path.empty()) return path;
  path = (fs::temp_directory_path() / ("bench_fit_all-" + std::to_string(getpid()) + ".db"));
  fs::remove(path);
  cleanup.base = path;
  station::Store store(path);
  for (int first = 0; first < serials; first += 16) {
    std::vector<std::string> names;
    std::vector<SyntheticGyro> gyros;
    for (int i = first; i < std::min(first + 16, serials); ++i) {
      names.push_back("SN" + std::to_string(100000 + i));
      SyntheticGyro g;
      g.seed = static_cast<std::uint64_t>(i) + 1;
      g.k1 = 1e-3 + 1e-6 * i;
      gyros.push_back(g);
    }
    station::testing_support::store_synthetic_run(store, names, gyros);
  }
  return path;
}

void BM_FitAll1000Serials(benchmark::State& state) {
  const int serials = static_cast<int>(state.range(0));
  const std::string& tmpl = template_db(serials);
  const std::string work = tmpl + ".work.db";
  for (auto _ : state) {
    state.PauseTiming();  // every iteration starts from the database without fits
    for (const char* ext : {"", "-wal", "-shm"}) fs::remove(work + ext);
    fs::copy_file(tmpl, work);
    state.ResumeTiming();
    station::Store store(work, station::OpenMode::existing);
    const auto result = station::fit_all(store, std::nullopt, {}, {});
    if (result.fits.size() != static_cast<std::size_t>(serials)) state.SkipWithError("fits lost");
    benchmark::DoNotOptimize(result.fits.data());
  }
  state.counters["fits_per_s"] = benchmark::Counter(static_cast<double>(serials),
                                                    benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_FitAll1000Serials)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same fits as before fit_all: one serial at a time, each fit its own autocommit
// transaction (what `fit --serial` per serial costs), for comparison.
void BM_FitEachSerialOnItsOwn(benchmark::State& state) {
  const int serials = static_cast<int>(state.range(0));
  const std::string& tmpl = template_db(serials);
  const std::string work = tmpl + ".each.db";
  for (auto _ : state) {
    state.PauseTiming();
    for (const char* ext : {"", "-wal", "-shm"}) fs::remove(work + ext);
    fs::copy_file(tmpl, work);
    state.ResumeTiming();
    station::Store store(work, station::OpenMode::existing);
    for (const auto& serial : station::all_serials(store))
      benchmark::DoNotOptimize(station::fit_serial(store, serial, {}, {}).fit_id);
  }
}
BENCHMARK(BM_FitEachSerialOnItsOwn)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
