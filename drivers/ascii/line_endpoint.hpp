// Endpoints of line-oriented ASCII devices: `tcp://HOST:PORT` (a raw TCP socket, e.g. the ESPEC
// P300's port 10001 or a serial-to-Ethernet server) and
// `serial:/dev/ttyX?baud=..&parity=..&data=..&stop=..` (RS-232/RS-485, 8N1 by default).
#pragma once

#include <string>
#include <string_view>
#include <variant>

namespace station::drivers::ascii {

/// A TCP socket carrying lines.
struct LineTcp {
  std::string host;  ///< IPv4/IPv6 literal ("localhost" reads as 127.0.0.1; no DNS: no deadline)
  int port = 0;      ///< 1..65535
};

/// A serial line carrying lines.
struct LineSerial {
  std::string device;  ///< e.g. /dev/ttyUSB0 or a pty slave
  int baud = 9600;     ///< one of the standard termios rates
  char parity = 'N';   ///< 'N', 'E' or 'O'
  int data_bits = 8;   ///< 7 or 8
  int stop_bits = 1;   ///< 1 or 2
};

/// Either transport.
using LineEndpoint = std::variant<LineTcp, LineSerial>;

/// Parses an endpoint string; throws std::invalid_argument naming the string and what is wrong.
LineEndpoint parse_line_endpoint(std::string_view text);
/// Canonical string form (round-trips through parse_line_endpoint).
std::string to_string(const LineEndpoint& ep);

}  // namespace station::drivers::ascii
