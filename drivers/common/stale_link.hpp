// The stale-link rule of every client that holds a link to its device (Modbus, ASCII lines):
// a TCP peer that rebooted leaves our socket half-open, so requests vanish without an RST and
// only a fresh connection recovers; a serial line has no connection to renew. No I/O.
#pragma once

#include "drivers/common/result.hpp"

namespace station::drivers {

/// Timeouts in a row after which a client on a connection (TCP) drops it; the next call
/// reconnects. A serial line only flushes.
inline constexpr int kTimeoutsBeforeReconnect = 3;

/// Counts timeouts in a row since the last answer of any kind.
class StaleLink {
 public:
  /// A reply arrived (or a fresh connection was made).
  void answered() { timeouts_ = 0; }
  /// Notes a failed exchange; true when the link must be reopened: it was lost, or
  /// kTimeoutsBeforeReconnect timeouts came in a row on a connection.
  bool must_reopen(ErrorKind kind, bool on_connection) {
    timeouts_ = kind == ErrorKind::timeout ? timeouts_ + 1 : 0;
    const bool reopen =
        kind == ErrorKind::disconnected || (on_connection && timeouts_ >= kTimeoutsBeforeReconnect);
    if (reopen) stale_timeouts_ = timeouts_, timeouts_ = 0;
    return reopen;
  }
  /// Timeouts in a row that made the last must_reopen() true (0 when the link was lost).
  int stale_timeouts() const { return stale_timeouts_; }

 private:
  int timeouts_ = 0;
  int stale_timeouts_ = 0;
};

}  // namespace station::drivers
