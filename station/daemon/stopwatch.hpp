// Adds the wall time of a scope to a running total: the sequencer's per-phase tick times.
#pragma once

#include <chrono>

namespace station {

/// Adds the steady-clock time from construction to destruction to `*total` (nullptr: nothing).
class Stopwatch {
 public:
  explicit Stopwatch(double* total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~Stopwatch() {
    if (total_ != nullptr)
      *total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  Stopwatch(const Stopwatch&) = delete;
  Stopwatch& operator=(const Stopwatch&) = delete;

 private:
  double* total_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace station
