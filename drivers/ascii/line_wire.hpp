// The raw link under LineClient, behind one small interface: a TCP socket or a termios serial
// line here; a recorded session answering from its log is the other implementation (replay).
// LineClient's error translation, reconnect and back-off run the same over both.
#pragma once

#include <chrono>
#include <string>
#include <string_view>

#include "drivers/ascii/line_endpoint.hpp"
#include "drivers/common/unique_fd.hpp"

namespace station::drivers::ascii {

/// One line link. Calls return 0 / a count, or -1 with errno set (ETIMEDOUT on a deadline).
class LineWire {
 public:
  virtual ~LineWire() = default;
  /// Opens the link; the connect waits at most `timeout_s`.
  virtual int open(double timeout_s) = 0;
  /// Closes the link; nothing when it is closed.
  virtual void close() = 0;
  /// Writes `bytes` (a command with its terminator) within `timeout_s`.
  virtual int send(std::string_view bytes, double timeout_s) = 0;
  /// Reads one line ending in `terminator` into `line` (terminator removed) within `timeout_s`;
  /// a line longer than `max_bytes` is EMSGSIZE.
  virtual int receive(std::string& line, std::string_view terminator, double timeout_s,
                      std::size_t max_bytes) = 0;
  /// Reads exactly `n` bytes into `bytes` within `timeout_s` (a length-prefixed frame's parts;
  /// bytes already read past a line come first); some but not all of them by then is EBADMSG.
  virtual int receive_exact(std::string& bytes, std::size_t n, double timeout_s) = 0;
  /// Discards unread input (before a request, after a timeout).
  virtual void flush() = 0;
};

/// The real link: a TCP socket or a raw-mode serial line. The constructor does no I/O.
class FdLineWire final : public LineWire {
 public:
  explicit FdLineWire(LineEndpoint endpoint) : endpoint_(std::move(endpoint)) {}
  int open(double timeout_s) override;
  void close() override;
  int send(std::string_view bytes, double timeout_s) override;
  int receive(std::string& line, std::string_view terminator, double timeout_s,
              std::size_t max_bytes) override;
  int receive_exact(std::string& bytes, std::size_t n, double timeout_s) override;
  void flush() override;

 private:
  int open_tcp(const LineTcp& ep, double timeout_s);
  int open_serial(const LineSerial& ep);
  /// Reads what the descriptor has into pending_, waiting until `deadline`.
  int fill(std::chrono::steady_clock::time_point deadline);

  LineEndpoint endpoint_;
  UniqueFd fd_;
  std::string pending_;  // bytes read past the last line
};

}  // namespace station::drivers::ascii
