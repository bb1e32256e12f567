// Test helper: a Clock that moves only when the test says so, for back-off schedules.
#pragma once

#include "drivers/common/clock.hpp"

namespace station::testing_support {

/// now_s() is whatever the test set; sleeping jumps to the deadline.
class ManualClock final : public drivers::Clock {
 public:
  double now_s() const override { return now_s_; }
  void sleep_until(double deadline_s) override {
    now_s_ = deadline_s > now_s_ ? deadline_s : now_s_;
  }
  bool wait_readable(int, double) override { return false; }
  /// Moves time forward by `s` seconds.
  void advance(double s) { now_s_ += s; }

 private:
  double now_s_ = 1000.0;
};

}  // namespace station::testing_support
