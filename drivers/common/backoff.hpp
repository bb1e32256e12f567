// Bounded exponential back-off between reconnect attempts of a transport (no I/O, no sleeping:
// the caller asks whether an attempt is due and reports how it went).
#pragma once

#include <algorithm>
#include <chrono>

#include "drivers/common/clock.hpp"

namespace station::drivers {

/// Reconnect schedule: after a failed attempt the next one is due `delay_s` later, the delay
/// doubling from initial_s up to max_s; a success resets it. The first attempt after a loss is
/// due at once. Times are seconds of `clock` (nullptr: the steady clock).
class Backoff {
 public:
  /// First delay after a failure and the cap, seconds.
  static constexpr double kInitialS = 0.5, kMaxS = 8.0;

  explicit Backoff(const Clock* clock = nullptr) : clock_(clock) {}

  /// Sets the time source (nullptr: steady clock). Not owned.
  void set_clock(const Clock* clock) { clock_ = clock; }
  /// Whether an attempt may be made now.
  bool due() const { return failures_ == 0 || now_s() >= next_s_; }
  /// Records a failed attempt: the next one is due after the current delay, which then doubles.
  void failed() {
    next_s_ = now_s() + delay_s_;
    delay_s_ = std::min(2 * delay_s_, kMaxS);
    ++failures_;
  }
  /// Records a successful attempt: the schedule starts over.
  void succeeded() {
    failures_ = 0;
    delay_s_ = kInitialS;
  }
  /// Failed attempts since the last success.
  int failures() const { return failures_; }
  /// Seconds until the next attempt is due (0 when due now).
  double wait_s() const { return due() ? 0.0 : next_s_ - now_s(); }

 private:
  double now_s() const {
    if (clock_ != nullptr) return clock_->now_s();
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }

  const Clock* clock_;
  double delay_s_ = kInitialS, next_s_ = 0;
  int failures_ = 0;
};

}  // namespace station::drivers
