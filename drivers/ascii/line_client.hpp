// A small client for line-oriented ASCII devices (ESPEC P300, ACUTROL3000): one command, at most
// one reply (a line, or a length-prefixed frame), each exchange bounded by one deadline. Errors
// become ErrorKind in one place; a lost link (or kTimeoutsBeforeReconnect timeouts in a row on TCP)
// is reopened on the next call after the same bounded back-off as ModbusClient. Every exchange
// passes the tap: kind "ascii" (tx: the bytes sent, terminator included; rx: the reply line without
// it, or every byte read for a frame and for a reply whose framing was recognized from its first
// bytes) and the events "ascii-connect", "ascii-disconnect", "ascii-error" (errno as 4 bytes, the
// message as detail).
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

/// A length-prefixed reply: a fixed header holding the payload's length (an unsigned 32-bit
/// little-endian number at `length_offset`), the payload, then a NUL that the length may or may
/// not count. A header always holds a NUL (a length below 2^24 has a zero high byte); a text line
/// never does: that tells a frame from a line by its first bytes.
struct FrameLayout {
  std::size_t header_bytes = 8;
  std::size_t length_offset = 4;
  std::size_t max_payload_bytes = 32768;  ///< a longer frame is a protocol error, never read
};

/// One reply: a frame's header and payload (its NUL removed), or a line (no header).
struct Reply {
  std::string header;
  std::string payload;
  bool framed() const { return !header.empty(); }
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
  /// Sends `command` and reads one length-prefixed frame (`layout`); a length beyond the
  /// layout's bound, a missing NUL or a frame cut short at the deadline is ErrorKind::protocol.
  Result<Reply> query_frame(std::string_view command, const FrameLayout& layout);
  /// Sends `command` and reads its reply as a frame or as a line, whichever its first bytes show
  /// (a NUL among the first header_bytes: a frame).
  Result<Reply> query_detect(std::string_view command, const FrameLayout& layout);

  const std::string& device() const { return device_; }
  const LineEndpoint& endpoint() const { return endpoint_; }
  double timeout_s() const { return timeout_s_; }

 private:
  /// The steady-clock second `timeout_s` from now; what is left of such a deadline (>= 0).
  static double deadline_after(double timeout_s);
  static double seconds_left(double deadline_s);
  Result<void> ensure_connected();
  Result<void> transmit(std::string_view command, double timeout_s);
  Error fail(int err, const std::string& what);
  /// A reply that arrived but breaks the framing: no tap of its own (the bytes were tapped),
  /// unread input discarded.
  Error malformed(std::string_view command, const std::string& what);
  /// Reads the rest of a frame whose first bytes are `raw`; taps every byte read.
  Result<Reply> finish_frame(std::string_view command, const FrameLayout& layout, std::string raw,
                             double deadline_s);
  /// Reads the rest of a line whose first bytes are `raw`; taps every byte read.
  Result<Reply> finish_line(std::string_view command, std::string raw, double deadline_s);
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
