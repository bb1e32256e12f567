// A bound on every device exchange a thread begins while it lasts, whatever the device's own
// timeout: the tick's budget for all of its device I/O (station/daemon/sequencer.cpp,
// kTickIoShare) and, within it, for its reads (station/daemon/rig_reading.cpp), so a chamber that
// used most of it leaves the turntable the rest, not a whole timeout past the tick (issue 34).
// The real links take it (LibmodbusWire, LineClient); a recorded session answers from its log.
#pragma once

#include <algorithm>
#include <chrono>
#include <optional>

namespace station::drivers {

/// Scoped: from construction to destruction, exchanges end by `until` at the latest (nested
/// scopes keep the earlier bound). Thread-local; no I/O.
class ExchangeDeadline {
 public:
  using Clock = std::chrono::steady_clock;
  explicit ExchangeDeadline(Clock::time_point until) : saved_(cap()) {
    cap() = saved_ ? std::min(*saved_, until) : until;
  }
  ~ExchangeDeadline() { cap() = saved_; }
  ExchangeDeadline(const ExchangeDeadline&) = delete;
  ExchangeDeadline& operator=(const ExchangeDeadline&) = delete;

  /// `own` (an exchange's own deadline) bounded by the scope's, if one is on.
  static Clock::time_point bound(Clock::time_point own) {
    return cap() ? std::min(own, *cap()) : own;
  }
  /// The same for a deadline in steady-clock seconds since its epoch.
  static double bound_s(double own_s) {
    if (!cap()) return own_s;
    return std::min(own_s, std::chrono::duration<double>(cap()->time_since_epoch()).count());
  }

 private:
  static std::optional<Clock::time_point>& cap() {
    thread_local std::optional<Clock::time_point> c;
    return c;
  }
  std::optional<Clock::time_point> saved_;
};

}  // namespace station::drivers
