// CLOCK_MONOTONIC with absolute-deadline sleeps.
#include "drivers/common/clock.hpp"

#include <poll.h>

#include <cerrno>
#include <cmath>
#include <ctime>

namespace station::drivers {

double MonotonicClock::now_s() const {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void MonotonicClock::sleep_until(double deadline_s) {
  timespec ts{};
  double whole = 0;
  const double frac = std::modf(deadline_s, &whole);
  ts.tv_sec = static_cast<time_t>(whole);
  ts.tv_nsec = static_cast<long>(frac * 1e9);
  // Absolute deadline: an interrupted sleep resumes toward the same instant.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

bool MonotonicClock::wait_readable(int fd, double deadline_s) {
  for (;;) {
    const double left_s = deadline_s - now_s();
    if (left_s <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(left_s * 1000.0) + 1);
    if (r > 0) return (p.revents & POLLIN) != 0;
    if (r == 0 || errno != EINTR) return false;
  }
}

}  // namespace station::drivers
