// Reading the session's line-oriented device logs (modbus.log, gpio.log; schemas/session.md),
// the inverse of format_session_line.
#pragma once

#include <cstdint>
#include <functional>
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

/// Calls `line(text, line_no)` for every line of `path` (or `path`.gz when only that exists),
/// read through zlib (a plain file reads as it is); returns the file actually read. Throws
/// InputError naming the file when it cannot be read or its compressed data is corrupt.
std::string for_each_line(const std::string& path,
                          const std::function<void(std::string_view, int)>& line);

/// Every CAN frame of a session's can.log (or can.log.gz); throws InputError "path:line: what".
std::vector<drivers::can::CandumpRecord> read_session_can_log(const std::string& path);

/// Every line of a log file (`path`, or `path`.gz read through zlib when only that exists);
/// throws InputError "path:line: what" on a malformed line or an unreadable file.
std::vector<SessionLogLine> read_session_log(const std::string& path);

/// The same, one line at a time (nothing held).
void read_session_log(const std::string& path, const std::function<void(SessionLogLine&&)>& each);

}  // namespace station
