// The benchmarks' main: the process set up as `station` sets itself up (station/main.cpp), so a
// figure measures what the station does.
#include <benchmark/benchmark.h>

#include "station/common/allocator.hpp"

int main(int argc, char** argv) {
  station::keep_freed_memory_for_reuse();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
