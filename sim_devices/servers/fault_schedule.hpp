// The injected link faults of one simulated server (Modbus or line), decided in one place:
// what the next request gets (no reply, the device's error, a dropped connection) and when the
// link is down. Thread-safe: the fault commands set it, the server thread takes from it.
// Durations run on the rig's own time: the wall clock under simrig, the simulated clock under
// `run --sim` (set_time_source), so a fault script means the same seconds on both.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <utility>

namespace station::sim {

class FaultSchedule {
 public:
  enum class Fault { none, timeout, exception, drop };
  /// Seconds on the rig's time; the default is the steady (wall) clock.
  using TimeSource = std::function<double()>;

  /// The clock durations run on (may be set while the server thread runs).
  void set_time_source(TimeSource now_s) {
    std::lock_guard lock(mutex_);
    now_s_ = std::move(now_s);
  }
  double now_s() const {
    std::lock_guard lock(mutex_);
    return now_s_();
  }

  void inject_timeouts(int n) {
    std::lock_guard lock(mutex_);
    timeouts_ = n;
  }
  void inject_exception(int code, int n) {
    std::lock_guard lock(mutex_);
    exception_code_ = code;
    exceptions_ = n;
  }
  void inject_drop(int n) {
    std::lock_guard lock(mutex_);
    drops_ = n;
  }
  void refuse_for(double seconds, int code) {
    std::lock_guard lock(mutex_);
    refuse_until_s_ = after(seconds);
    refuse_code_ = code;
  }
  void stall_for(double seconds) {
    std::lock_guard lock(mutex_);
    stall_until_s_ = after(seconds);
  }
  void drip_for(double seconds, double byte_interval_s) {
    std::lock_guard lock(mutex_);
    drip_until_s_ = after(seconds);
    drip_interval_s_ = std::max(0.0, byte_interval_s);
  }
  /// Seconds between the bytes of a reply sent now (0: the reply leaves at once).
  double drip_interval_s() const {
    std::lock_guard lock(mutex_);
    return now_s_() < drip_until_s_ ? drip_interval_s_ : 0.0;
  }
  void disconnect_for(double seconds) {
    std::lock_guard lock(mutex_);
    down_until_s_ = after(seconds);
    ++kicks_;
  }
  void clear() {
    std::lock_guard lock(mutex_);
    timeouts_ = exceptions_ = drops_ = 0;
    stall_until_s_ = down_until_s_ = refuse_until_s_ = drip_until_s_ = kNever;
  }
  /// What the request just received gets; `code` is set for an exception. While stalled or
  /// down (a serial line is silent when its device is off) nothing answers.
  Fault take(int& code) {
    std::lock_guard lock(mutex_);
    const double now = now_s_();
    if (now < stall_until_s_ || now < down_until_s_) return Fault::timeout;
    if (timeouts_ > 0) return --timeouts_, Fault::timeout;
    if (now < refuse_until_s_) {
      code = refuse_code_;
      return Fault::exception;
    }
    if (drops_ > 0) return --drops_, Fault::drop;
    if (exceptions_ != 0) {
      code = exception_code_;
      if (exceptions_ > 0) --exceptions_;
      return Fault::exception;
    }
    return Fault::none;
  }
  /// Disconnects asked so far (a server closes its connections once per new one), and until
  /// when the link stays down (on now_s()).
  std::uint64_t kicks(double& down_until_s) const {
    std::lock_guard lock(mutex_);
    down_until_s = down_until_s_;
    return kicks_;
  }

 private:
  static constexpr double kNever = -std::numeric_limits<double>::infinity();
  static double steady_s() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  double after(double seconds) const { return now_s_() + std::max(0.0, seconds); }

  mutable std::mutex mutex_;
  TimeSource now_s_ = steady_s;
  int timeouts_ = 0, exceptions_ = 0, exception_code_ = 0, drops_ = 0;
  double stall_until_s_ = kNever, down_until_s_ = kNever, refuse_until_s_ = kNever;
  double drip_until_s_ = kNever, drip_interval_s_ = 0;
  int refuse_code_ = 0;
  std::uint64_t kicks_ = 0;
};

}  // namespace station::sim
