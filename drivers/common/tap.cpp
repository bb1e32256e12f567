// Wall-clock stamping for tap records.
#include "drivers/common/tap.hpp"

#include <ctime>

namespace station::drivers {

double tap_wall_time_s() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace station::drivers
