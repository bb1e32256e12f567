// `run --sim --speed X`: the simulated clock paced against the monotonic one, X simulated
// seconds per wall second, so a person can watch a simulated run (600: 13 h in ~80 s).
#pragma once

#include "drivers/common/clock.hpp"

namespace station {

/// Moves `sim` (which the simulators share) and sleeps so that simulated time never runs ahead
/// of speed × wall time since construction. A tick that took longer is not made up for.
class PacedClock final : public drivers::Clock {
 public:
  PacedClock(drivers::Clock& sim, double speed);
  double now_s() const override { return sim_.now_s(); }
  void sleep_until(double deadline_s) override;
  bool wait_readable(int fd, double deadline_s) override {
    return sim_.wait_readable(fd, deadline_s);
  }

 private:
  drivers::Clock& sim_;
  drivers::MonotonicClock wall_;
  double speed_;
  double sim0_s_, wall0_s_;
};

}  // namespace station
