// Whether a client's link to its device is open, and when it may try again (Modbus, ASCII
// lines): the connect count a driver watches for a device restart, the back-off between
// attempts and the last attempt's error. No I/O: the client opens and closes its wire.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <string>
#include <utility>

#include "drivers/common/backoff.hpp"
#include "drivers/common/result.hpp"

namespace station::drivers {

class LinkState {
 public:
  /// The time source of the back-off (nullptr: steady clock). Not owned.
  void set_clock(const Clock* clock) { backoff_.set_clock(clock); }
  bool connected() const { return connected_; }
  /// Successful connects so far (a change tells a driver the device may have restarted).
  std::uint64_t connects() const { return connects_; }

  /// Open: nothing to do. Closed: `connect()` when an attempt is due (Backoff: at once after a
  /// loss, then 0.5, 1, 2 ... 8 s apart), else ErrorKind::disconnected naming the wait and the
  /// last attempt's error, without I/O.
  template <class Connect>
  Result<void> ensure(const std::string& device, Connect&& connect) {
    if (connected_) return {};
    if (!backoff_.due())
      return make_error(ErrorKind::disconnected,
                        fmt::format("{}: not connected, next attempt in {:.1f} s ({})", device,
                                    backoff_.wait_s(), last_error_));
    return connect();
  }
  /// An attempt failed with `message`: the next one waits.
  void connect_failed(std::string message) {
    backoff_.failed();
    last_error_ = std::move(message);
  }
  /// An attempt succeeded: open, one more connect, the back-off starts over.
  void connect_succeeded() {
    backoff_.succeeded();
    connected_ = true;
    ++connects_;
  }
  /// The link was closed by us.
  void closed() { connected_ = false; }
  /// The link was found lost with `message` (said while no attempt is due); the first attempt
  /// after a loss is due at once.
  void lost(std::string message) {
    connected_ = false;
    last_error_ = std::move(message);
  }
  const std::string& last_error() const { return last_error_; }

 private:
  bool connected_ = false;
  std::uint64_t connects_ = 0;
  Backoff backoff_;
  std::string last_error_;
};

}  // namespace station::drivers
