// Reading the session's line-oriented device logs (modbus.log, gpio.log; schemas/session.md),
// the inverse of format_session_line.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/can/candump_log.hpp"
#include "drivers/common/result.hpp"

namespace station {

/// One line of modbus.log or gpio.log.
struct SessionLogLine {
  double t_s = 0;
  std::string device, direction, kind;  ///< direction: tx | rx | event
  std::vector<std::uint8_t> bytes;
  std::string detail;
  int line_no = 0;  ///< 1-based, for messages
};

/// Parses one line ("TIME DEVICE DIRECTION KIND HEX DETAIL..."); a protocol error saying what is
/// malformed.
drivers::Result<SessionLogLine> parse_session_line(std::string_view line);

/// A log file (`path`, or `path`.gz when only that exists) read a line at a time through zlib (a
/// plain file reads as it is), in chunks of up to 1 MiB: nothing held but the chunk.
class LogLineReader {
 public:
  /// Throws InputError naming the file when it cannot be opened.
  explicit LogLineReader(const std::string& path);
  ~LogLineReader();
  LogLineReader(LogLineReader&&) noexcept;
  /// The next non-empty line (without its newline or a CR before it; valid until the next call)
  /// and its 1-based number; false at the end. Throws InputError "FILE:LINE: corrupt compressed
  /// data".
  bool next(std::string_view& line, int& line_no);
  /// The file actually read.
  const std::string& file() const { return file_; }

 private:
  bool refill();
  struct Gz;
  std::string file_;
  std::unique_ptr<Gz> in_;
  std::size_t chunk_ = 0;
  std::string buf_;
  std::size_t begin_ = 0;  // first byte of buf_ not yet handed out
  int line_no_ = 0;
  bool eof_ = false;
};

/// Calls `line(text, line_no)` for every line of `path` (or `path`.gz when only that exists),
/// read through zlib (a plain file reads as it is); returns the file actually read. Throws
/// InputError naming the file when it cannot be read or its compressed data is corrupt.
std::string for_each_line(const std::string& path,
                          const std::function<void(std::string_view, int)>& line);

/// A session log (modbus.log, gpio.log, ascii.log) parsed a line at a time, one line ahead.
class SessionLogStream {
 public:
  explicit SessionLogStream(const std::string& path) : reader_(path) {}
  /// The next line, nullptr at the end; throws InputError "FILE:LINE: what" for a malformed one.
  const SessionLogLine* peek();
  /// Takes the line peek() gave.
  SessionLogLine take();

 private:
  LogLineReader reader_;
  std::optional<SessionLogLine> next_;
};

/// A session's can.log (or can.log.gz) parsed a record at a time (blank lines skipped).
class CanLogStream {
 public:
  explicit CanLogStream(const std::string& path) : reader_(path) {}
  /// The next record; false at the end. Throws InputError "FILE:LINE: what".
  bool next(drivers::can::CandumpRecord& record);

 private:
  LogLineReader reader_;
};

/// Every CAN frame of a session's can.log (or can.log.gz); throws InputError "path:line: what".
std::vector<drivers::can::CandumpRecord> read_session_can_log(const std::string& path);

/// Every line of a log file (`path`, or `path`.gz read through zlib when only that exists);
/// throws InputError "path:line: what" on a malformed line or an unreadable file.
std::vector<SessionLogLine> read_session_log(const std::string& path);

/// The same, one line at a time (nothing held).
void read_session_log(const std::string& path, const std::function<void(SessionLogLine&&)>& each);

}  // namespace station
