// A CAN transport that comes back: it reopens `unix:` and `socketcan:` links after a loss, with
// bounded exponential back-off, so a restarted bus peer or a replugged adapter is picked up again.
#pragma once

#include <memory>
#include <string>

#include "drivers/can/can_transport.hpp"
#include "drivers/common/link_state.hpp"

namespace station::drivers::can {

/// Owns the transport a spec names and reopens it when it is lost (ErrorKind::disconnected):
/// the first attempt on the next call, then after 0.5, 1, 2, 4, 8, 8 ... s (Backoff). A call
/// made while the next attempt is not due returns ErrorKind::disconnected at once, so no call
/// blocks longer than the transport's own timeouts. An inherited `fd:` cannot be reopened: it
/// is kept and read again on every call, and its errors say so.
class ReconnectingCanTransport final : public CanTransport {
 public:
  /// Stores spec and options; no I/O (the first call, or open(), opens the link).
  ReconnectingCanTransport(CanSpec spec, CanOpenOptions options);

  /// Opens the link now if it is down (whatever the back-off says); the error names the spec.
  Result<void> open();
  Result<void> send(const can_frame& frame) override;
  Result<can_frame> receive(std::chrono::milliseconds timeout) override;
  /// The current link's descriptor, -1 while it is down.
  int fd() const override;
  double last_rx_time_s() const override { return last_rx_time_s_; }

  /// Whether a link is open now.
  bool link_up() const { return link_ != nullptr; }
  /// Times the link was reopened after a loss.
  int reconnects() const {
    return state_.connects() > 0 ? static_cast<int>(state_.connects() - 1) : 0;
  }
  /// The spec as text (`unix:PATH`, ...).
  const std::string& name() const { return name_; }

 private:
  Result<void> ensure_open();
  Error lost(Error e);
  void tap_event(const char* kind, const std::string& detail) const;

  CanSpec spec_;
  CanOpenOptions options_;
  std::string name_;
  std::unique_ptr<CanTransport> link_;
  LinkState state_;  ///< open or not (mirrors link_), and when the next attempt is due
  double last_rx_time_s_ = 0;
};

}  // namespace station::drivers::can
