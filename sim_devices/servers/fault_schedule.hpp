// The injected link faults of one simulated server (Modbus or line), decided in one place:
// what the next request gets (no reply, the device's error, a dropped connection) and when the
// link is down. Thread-safe: the fault commands set it, the server thread takes from it.
#pragma once

#include <algorithm>
#include <chrono>
#include <mutex>
#include <utility>

namespace station::sim {

class FaultSchedule {
 public:
  enum class Fault { none, timeout, exception, drop };
  using SteadyTime = std::chrono::steady_clock::time_point;

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
  void stall_for(double seconds) {
    std::lock_guard lock(mutex_);
    stall_until_ = after(seconds);
  }
  void disconnect_for(double seconds) {
    std::lock_guard lock(mutex_);
    down_until_ = after(seconds);
    kick_clients_ = true;
  }
  void clear() {
    std::lock_guard lock(mutex_);
    timeouts_ = exceptions_ = drops_ = 0;
    stall_until_ = down_until_ = {};
    kick_clients_ = false;
  }
  /// What the request just received gets; `code` is set for an exception. While stalled or
  /// down (a serial line is silent when its device is off) nothing answers.
  Fault take(int& code) {
    std::lock_guard lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (now < stall_until_ || now < down_until_) return Fault::timeout;
    if (timeouts_ > 0) return --timeouts_, Fault::timeout;
    if (drops_ > 0) return --drops_, Fault::drop;
    if (exceptions_ != 0) {
      code = exception_code_;
      if (exceptions_ > 0) --exceptions_;
      return Fault::exception;
    }
    return Fault::none;
  }
  /// Whether a disconnect was asked since the last call (its clients are to be closed now), and
  /// until when the link stays down.
  bool take_kick(SteadyTime& down_until) {
    std::lock_guard lock(mutex_);
    down_until = down_until_;
    return std::exchange(kick_clients_, false);
  }

 private:
  static SteadyTime after(double seconds) {
    const std::chrono::duration<double> d(std::max(0.0, seconds));
    return std::chrono::steady_clock::now() +
           std::chrono::duration_cast<std::chrono::steady_clock::duration>(d);
  }

  std::mutex mutex_;
  int timeouts_ = 0, exceptions_ = 0, exception_code_ = 0, drops_ = 0;
  SteadyTime stall_until_{}, down_until_{};
  bool kick_clients_ = false;
};

}  // namespace station::sim
