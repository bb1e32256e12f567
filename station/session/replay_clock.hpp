// Virtual time for a replay: sleeps return at once; a wait on an fd returns true when the fd is
// readable now (a replayed GPIO edge), else jumps to the deadline. No wall-clock waits at all.
#pragma once

#include <poll.h>

#include "drivers/common/clock.hpp"

namespace station {

class ReplayClock final : public drivers::Clock {
 public:
  double now_s() const override { return now_s_; }
  void sleep_until(double deadline_s) override {
    if (deadline_s > now_s_) now_s_ = deadline_s;
  }
  bool wait_readable(int fd, double deadline_s) override {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 0) == 1 && (p.revents & POLLIN) != 0) return true;
    sleep_until(deadline_s);
    return false;
  }

 private:
  double now_s_ = 0;
};

}  // namespace station
