// A small client for line-oriented ASCII devices (ESPEC P300, ACUTROL3000): one command, at most
// one reply line, each exchange bounded by its timeout. Errors become ErrorKind in one place; a
// lost link (or kTimeoutsBeforeReconnect timeouts in a row on TCP) is reopened on the next call
// after the same bounded back-off as ModbusClient. Every exchange passes the tap: kind "ascii"
// (tx: the bytes sent, terminator included; rx: the reply line without it) and the events
// "ascii-connect", "ascii-disconnect", "ascii-error" (errno as 4 bytes, the message as detail).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "drivers/ascii/line_endpoint.hpp"
#include "drivers/ascii/line_wire.hpp"
#include "drivers/common/link_state.hpp"
#include "drivers/common/result.hpp"
#include "drivers/common/stale_link.hpp"
#include "drivers/common/tap.hpp"

namespace station::drivers::ascii {

/// How a dialect frames its lines (from the dialect's source, see its wire header).
struct LineFraming {
  std::string command_terminator = "\r\n";  ///< appended to every command
  std::string reply_terminator = "\r\n";    ///< ends every reply line
  std::size_t max_reply_bytes = 512;        ///< a longer reply is a protocol error
};

/// Translates an errno from a failed LineWire call into a typed Error (the one place).
Error translate_line_error(int err, const std::string& what);

/// Master for one line device. Not thread-safe; one caller at a time.
class LineClient {
 public:
  /// Stores the parameters; no I/O. `wire` nullptr: FdLineWire on `endpoint`.
  LineClient(std::string device, LineEndpoint endpoint, LineFraming framing,
             std::unique_ptr<LineWire> wire = nullptr, double timeout_s = 0.5);

  /// Sets the tap every exchange passes (nullptr: none). Not owned.
  void set_tap(Tap* tap) { tap_ = tap; }
  /// Sets the time source of the reconnect back-off (nullptr: steady clock). Not owned.
  void set_clock(const Clock* clock) { state_.set_clock(clock); }
  /// Opens the link now, whatever the back-off says; blocks up to the timeout.
  Result<void> connect();
  /// Closes the link; the next call reconnects.
  void disconnect();
  bool connected() const { return state_.connected(); }
  /// Successful connects so far (a change tells a driver the device may have restarted).
  std::uint64_t connects() const { return state_.connects(); }

  /// Sends `command` and returns the one reply line (terminator removed). Unread input is
  /// discarded first, so a late reply to an earlier command is never taken for this one's.
  Result<std::string> query(std::string_view command);
  /// Sends `command`, expecting no reply.
  Result<void> send(std::string_view command);

  const std::string& device() const { return device_; }
  const LineEndpoint& endpoint() const { return endpoint_; }
  double timeout_s() const { return timeout_s_; }

 private:
  Result<void> ensure_connected();
  Result<void> transmit(std::string_view command);
  Error fail(int err, const std::string& what);
  void tap(TapDirection dir, const char* kind, std::string_view bytes, std::string detail);

  std::string device_;
  LineEndpoint endpoint_;
  LineFraming framing_;
  double timeout_s_;
  std::unique_ptr<LineWire> wire_;
  Tap* tap_ = nullptr;
  StaleLink link_;   ///< the stale-link rule (drivers/common/stale_link.hpp)
  LinkState state_;  ///< open or not, and when the next connect attempt is due
};

}  // namespace station::drivers::ascii
