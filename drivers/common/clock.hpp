// Injected time: the sequencer schedules on a Clock — CLOCK_MONOTONIC in production, a simulated
// clock in tests and simulation (clknetsim's idea, in-process).
#pragma once

#include <chrono>

namespace station::drivers {

/// Steady time since an arbitrary epoch, in seconds.
using SteadySeconds = std::chrono::duration<double>;

/// A source of steady time that can sleep to an absolute deadline.
class Clock {
 public:
  virtual ~Clock() = default;
  /// Current steady time, seconds since the clock's epoch. Never blocks.
  virtual double now_s() const = 0;
  /// Blocks until now_s() >= deadline_s (a simulated clock jumps and returns at once).
  virtual void sleep_until(double deadline_s) = 0;
  /// Blocks until `fd` is readable (true) or the deadline passes (false). A simulated clock
  /// returns false at once: simulated inputs change only between ticks.
  virtual bool wait_readable(int fd, double deadline_s) = 0;
};

/// CLOCK_MONOTONIC, with clock_nanosleep(TIMER_ABSTIME) so deadlines do not drift.
class MonotonicClock final : public Clock {
 public:
  double now_s() const override;
  void sleep_until(double deadline_s) override;
  bool wait_readable(int fd, double deadline_s) override;
};

}  // namespace station::drivers
