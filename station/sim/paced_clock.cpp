// Paced simulated clock: wall deadline = start + simulated elapsed / speed.
#include "station/sim/paced_clock.hpp"

#include <algorithm>

namespace station {

PacedClock::PacedClock(drivers::Clock& sim, double speed)
    : sim_(sim), speed_(speed), sim0_s_(sim.now_s()), wall0_s_(wall_.now_s()) {}

void PacedClock::sleep_until(double deadline_s) {
  const double wall_deadline = wall0_s_ + (deadline_s - sim0_s_) / speed_;
  // Behind by more than a second of wall time (a slow tick, a stopped debugger): re-anchor
  // rather than race to catch up.
  if (wall_.now_s() > wall_deadline + 1.0) {
    sim0_s_ = deadline_s;
    wall0_s_ = wall_.now_s();
  } else {
    wall_.sleep_until(wall_deadline);
  }
  sim_.sleep_until(deadline_s);
}

}  // namespace station
