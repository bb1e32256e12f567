// Simulated time shared by the simulators and the sequencer: it only moves when asked.
#pragma once

#include "drivers/common/clock.hpp"

namespace station::sim {

/// A Clock whose sleep_until jumps to the deadline at once; deterministic and thread-compatible
/// (advance from one thread).
class SimClock final : public drivers::Clock {
 public:
  explicit SimClock(double start_s = 0.0) : now_s_(start_s) {}
  double now_s() const override { return now_s_; }
  void sleep_until(double deadline_s) override;
  bool wait_readable(int, double) override { return false; }

 private:
  double now_s_;
};

}  // namespace station::sim
