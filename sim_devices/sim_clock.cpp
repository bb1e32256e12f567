// Simulated clock: jumps to each deadline.
#include "sim_devices/sim_clock.hpp"

namespace station::sim {

void SimClock::sleep_until(double deadline_s) {
  if (deadline_s > now_s_) now_s_ = deadline_s;
}

}  // namespace station::sim
