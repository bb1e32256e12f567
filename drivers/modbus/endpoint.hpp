// Modbus endpoints: parsing `tcp://HOST:PORT` and
// `rtu:/dev/ttyX?baud=..&parity=..&data=..&stop=..`.
#pragma once

#include <string>
#include <string_view>
#include <variant>

namespace station::drivers::modbus {

/// Modbus TCP server address.
struct TcpEndpoint {
  std::string host;  ///< IPv4 address or host name
  int port = 502;    ///< 1..65535
};

/// Modbus RTU serial line.
struct RtuEndpoint {
  std::string device;  ///< e.g. /dev/ttyUSB0 or a pty slave
  int baud = 19200;    ///< bits per second
  char parity = 'N';   ///< 'N', 'E' or 'O'
  int data_bits = 8;   ///< 5..8
  int stop_bits = 1;   ///< 1 or 2
};

/// Either transport.
using Endpoint = std::variant<TcpEndpoint, RtuEndpoint>;

/// Parses an endpoint string; throws std::invalid_argument naming the string and what is wrong.
Endpoint parse_endpoint(std::string_view text);

/// Canonical string form (round-trips through parse_endpoint).
std::string to_string(const Endpoint& ep);

}  // namespace station::drivers::modbus
