// The raw Modbus link under ModbusClient, behind one small interface: libmodbus on a TCP socket
// or a serial line here; a recorded session answering from its log is the other implementation
// (replay). ModbusClient's error translation, reconnect and back-off run the same over both.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

#include "drivers/modbus/endpoint.hpp"
#include "drivers/modbus/modbus_frame.hpp"
#include "drivers/modbus/modbus_handle.hpp"
#include "drivers/modbus/register_map.hpp"

namespace station::drivers::modbus {

/// One read of a batch (ModbusWire::read_batch): `count` registers (function `fc`) of `unit` at
/// PDU address `addr`, decoded into `dest` (count words).
struct ReadRequest {
  FunctionCode fc = FunctionCode::holding;
  int unit = 1;
  std::uint16_t addr = 0;
  int count = 1;
  std::uint16_t* dest = nullptr;
};

/// One Modbus link. Calls return like libmodbus's: 0 / a count, or -1 with errno set.
class ModbusWire {
 public:
  virtual ~ModbusWire() = default;
  /// Opens the link, every later exchange bounded as a whole (request sent to the reply's last
  /// byte) by `timeout_s`; the connect waits at most as long. May throw
  /// std::runtime_error for parameters the transport rejects (no I/O happened then).
  virtual int open(double timeout_s) = 0;
  /// Closes the link; nothing when it is closed.
  virtual void close() = 0;
  /// Reads `count` registers (function `fc`) of `unit` at PDU address `addr` into `dest`.
  virtual int read(FunctionCode fc, int unit, std::uint16_t addr, int count,
                   std::uint16_t* dest) = 0;
  /// Reads `requests` as one batch: returns how many of them, from the first, were answered; when
  /// fewer than all, errno says why the next one failed (as read() would). Here one read() after
  /// another, stopping at the first failure; a link that may have several requests outstanding
  /// sends them back to back (LibmodbusWire on TCP).
  virtual int read_batch(std::span<const ReadRequest> requests);
  /// Writes holding registers of `unit` at `addr` (function 6 for one word, 16 for more).
  virtual int write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) = 0;
  /// Discards unread input (after a timeout or a garbled reply).
  virtual void flush() = 0;
  /// Keeps at least `gap_s` seconds between the end of one exchange (reply, exception or
  /// timeout) and the next request: the pause a dialect's source asks on a serial line
  /// (drivers/registry/dialects.cpp). Only a real line waits; a recording has no line to rest.
  virtual void set_request_gap_s(double /*gap_s*/) {}
};

/// The real link: libmodbus opens it (TCP connect, RTU serial setup); the exchanges are this
/// class's own, each bounded as a whole by one deadline of `timeout_s` (open()) from its start (the
/// request gap kept), however the reply's bytes are spaced (modbus_frame.hpp says why libmodbus
/// cannot bound it so), and by an active ExchangeDeadline (exchange_deadline.hpp): the request gap,
/// the dropping of a late reply, the quiet wait (below), the send and the reply all end by it, and
/// a connect waits at most what is left of it (a TCP host name that resolves to several addresses:
/// that much per address; the name lookup itself is not bounded). No reply by the deadline is
/// ETIMEDOUT, a reply begun but not finished by it (or one still arriving when the next request is
/// due) ETIME. What holds for late bytes: on TCP a late reply is told by its transaction id and
/// dropped, never read as the next reply. On RTU a frame has no id: the rest of a reply begun is
/// framed and dropped as it comes; after a timeout the next request is sent only once the line has
/// been quiet for quiet_interval_s() (bytes that come meanwhile are dropped), so a late reply that
/// begins within that interval of the timeout, or of the last byte seen, is never read as the next
/// reply; one a device sends later still (outside the protocol: Serial Line v1.02 §2.4.1 sets the
/// response timeout longer than any answer takes) can be. The constructor does no I/O.
class LibmodbusWire final : public ModbusWire {
 public:
  explicit LibmodbusWire(Endpoint endpoint) : endpoint_(std::move(endpoint)) {}
  int open(double timeout_s) override;
  void close() override;
  int read(FunctionCode fc, int unit, std::uint16_t addr, int count, std::uint16_t* dest) override;
  /// TCP (no request gap): every request sent back to back in one send, then the replies matched
  /// to them by transaction id in whatever order they come (Modbus Messaging on TCP/IP
  /// Implementation Guide v1.0b §3.1.3, §4.2: a server may serve several transactions at once),
  /// the whole batch bounded by one deadline as one exchange is. What fails is what failed the
  /// same request read alone: no reply by the deadline (ETIMEDOUT, ETIME when begun), a reply
  /// that answers no request of the batch (EMBBADDATA) or answers it wrongly (check_reply); the
  /// requests after it are abandoned, their late replies dropped by id. RTU, a gap, or one
  /// request: read() one after another.
  int read_batch(std::span<const ReadRequest> requests) override;
  int write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) override;
  void flush() override;
  void set_request_gap_s(double gap_s) override { gap_ = to_steady(gap_s); }
  /// RTU: the silence the line must keep after a timeout before the next request (s): a quarter
  /// of the timeout, and at least the 3.5 character times that end a frame (Serial Line v1.02
  /// §2.5.1.1: at the endpoint's baud, start, data, parity and stop bits; 1.75 ms above 19200
  /// baud).
  static double quiet_interval_s(const RtuEndpoint& ep, double timeout_s);

 private:
  using SteadyClock = std::chrono::steady_clock;
  static SteadyClock::duration to_steady(double s) {
    return std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(s));
  }
  /// Sleeps out what is left of the gap since the last exchange ended, if it ends before the
  /// deadline; false (no wait) when it does not.
  bool rest(SteadyClock::time_point deadline);
  /// RTU after a timeout: drops what comes until the line has been quiet for quiet_; 0, or -1
  /// with errno (ETIMEDOUT: not quiet by the deadline, so nothing may be sent).
  int wait_quiet(SteadyClock::time_point deadline);
  /// Marks the end of an exchange; returns `rc`.
  int ended(int rc);
  /// Before a request: the gap, a late reply's rest, the quiet wait (RTU), all by the deadline;
  /// 0, or -1 with errno (nothing may be sent).
  int begin(SteadyClock::time_point deadline);
  /// Sends the request `adu` (unit id and PDU) and reads its reply into `reply` by one deadline;
  /// 0, or -1 with errno set.
  int exchange(const std::vector<std::uint8_t>& adu, std::vector<std::uint8_t>& reply);
  /// Reads the rest of the frame begun in `frame` until the deadline, first from what was read
  /// ahead (rx_); 0 or -1 with errno.
  int receive_frame(std::vector<std::uint8_t>& frame, SteadyClock::time_point deadline);
  /// The next whole frame of a batch's replies: whatever the socket holds is read ahead into rx_
  /// (several replies in one read), the frame cut from it; 0 or -1 with errno (`frame` holds the
  /// part of a frame begun).
  int receive_batch_frame(std::vector<std::uint8_t>& frame, SteadyClock::time_point deadline);
  /// Reads the replies to a batch of read `requests` sent as `frames`, by the deadline, each
  /// into its dest; returns how many from the first were answered, errno set when not all.
  int collect_batch(std::span<const ReadRequest> requests,
                    const std::vector<std::vector<std::uint8_t>>& frames,
                    SteadyClock::time_point deadline);
  /// Remembers the transaction id of a request abandoned before its reply came (TCP).
  void abandon(std::uint16_t tid);
  /// Drops the rest of an abandoned reply (late_), reading until the deadline; 0 or -1.
  int drop_late(SteadyClock::time_point deadline);
  /// Writes the whole request frame by the deadline; 0 or -1 with errno.
  int send_frame(const std::vector<std::uint8_t>& frame, SteadyClock::time_point deadline);
  Framing framing() const;

  Endpoint endpoint_;
  ModbusHandle ctx_;
  SteadyClock::duration timeout_{0};
  SteadyClock::duration gap_{0};
  SteadyClock::duration quiet_{0};         ///< quiet_interval_s() (RTU)
  bool in_flight_ = false;                 ///< RTU: a timed-out reply may still be on its way
  SteadyClock::time_point quiet_since_{};  ///< RTU: the timeout, or the last byte dropped since
  SteadyClock::time_point last_end_{};
  std::uint16_t tid_ = 0;                ///< the last request's transaction id (TCP)
  std::vector<std::uint8_t> late_;       ///< the bytes read of a reply abandoned at its deadline
  std::vector<std::uint16_t> late_ids_;  ///< transaction ids of replies abandoned before a byte
  std::vector<std::uint8_t> rx_;         ///< bytes a batch read ahead, not yet framed (TCP)
};

}  // namespace station::drivers::modbus
