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
#include "station/session/session_digest.hpp"

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

/// A log file (`path`, or `path`.gz when only that exists) read a line at a time, decompressed as
/// it is read (DecompressedReader: a plain file as it is): nothing held but a chunk.
class LogLineReader {
 public:
  /// Throws InputError naming the file when it cannot be opened.
  explicit LogLineReader(const std::string& path);
  ~LogLineReader();
  /// Hands every byte read from now on to `digest` (whose file this is), before it is split.
  void digest_into(DigestBuilder* digest) { digest_ = digest; }
  /// The next non-empty line (without its newline or a CR before it; valid until the next call)
  /// and its 1-based number; false at the end. Throws InputError "FILE:LINE: what" for corrupt
  /// compressed data (the digest is told).
  bool next(std::string_view& line, int& line_no);
  /// The file actually read.
  const std::string& file() const { return file_; }

 private:
  bool refill();
  std::string file_;
  std::unique_ptr<DecompressedReader> in_;
  DigestBuilder* digest_ = nullptr;
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
  explicit SessionLogStream(const std::string& path)
      : own_(std::make_unique<LogLineReader>(path)), reader_(*own_) {}
  /// Over `reader` (SessionReads: verified as it is read).
  explicit SessionLogStream(LogLineReader& reader) : reader_(reader) {}
  /// The next line, nullptr at the end; throws InputError "FILE:LINE: what" for a malformed one.
  const SessionLogLine* peek();
  /// Takes the line peek() gave.
  SessionLogLine take();

 private:
  std::unique_ptr<LogLineReader> own_;
  LogLineReader& reader_;
  std::optional<SessionLogLine> next_;
};

/// A session's can.log (or can.log.gz) parsed a record at a time (blank lines skipped).
class CanLogStream {
 public:
  explicit CanLogStream(const std::string& path)
      : own_(std::make_unique<LogLineReader>(path)), reader_(*own_) {}
  /// Over `reader` (SessionReads: verified as it is read).
  explicit CanLogStream(LogLineReader& reader) : reader_(reader) {}
  /// The next record; false at the end. Throws InputError "FILE:LINE: what".
  bool next(drivers::can::CandumpRecord& record);

 private:
  std::unique_ptr<LogLineReader> own_;
  LogLineReader& reader_;
};

/// Every CAN frame of a session's can.log (or can.log.gz); throws InputError "path:line: what".
std::vector<drivers::can::CandumpRecord> read_session_can_log(const std::string& path);

/// Every line of a log file (`path`, or `path`.gz read through zlib when only that exists);
/// throws InputError "path:line: what" on a malformed line or an unreadable file.
std::vector<SessionLogLine> read_session_log(const std::string& path);

/// The same, one line at a time (nothing held).
void read_session_log(const std::string& path, const std::function<void(SessionLogLine&&)>& each);

}  // namespace station
