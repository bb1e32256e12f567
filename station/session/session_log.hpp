// Reading the session's line-oriented device logs (modbus.log, gpio.log; schemas/session.md),
// the inverse of format_session_line.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

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

/// Every line of a log file (`path`, or `path`.gz read through zlib when only that exists);
/// throws InputError "path:line: what" on a malformed line or an unreadable file.
std::vector<SessionLogLine> read_session_log(const std::string& path);

}  // namespace station
