// Line endpoint parsing with errors that name the offending part.
#include "drivers/ascii/line_endpoint.hpp"

#include <arpa/inet.h>

#include <array>
#include <charconv>
#include <stdexcept>

#include "drivers/common/endpoint_field.hpp"

namespace station::drivers::ascii {
namespace {

[[noreturn]] void fail(std::string_view text, const std::string& what) {
  endpoint_error("line", text, what);
}

int parse_int(std::string_view text, std::string_view key, std::string_view value, int lo, int hi) {
  return endpoint_int("line", text, key, value, lo, hi);
}

// The rates termios can set (cfsetspeed's B* constants up to 230400).
constexpr std::array kBauds{300, 600, 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400};

void apply_option(std::string_view text, LineSerial& ep, std::string_view kv) {
  const auto eq = kv.find('=');
  if (eq == std::string_view::npos) fail(text, "option '" + std::string(kv) + "' lacks '='");
  const auto key = kv.substr(0, eq);
  const auto value = kv.substr(eq + 1);
  if (key == "baud") {
    ep.baud = parse_int(text, "baud", value, 300, 230400);
    bool standard = false;
    for (int b : kBauds) standard = standard || b == ep.baud;
    if (!standard) fail(text, "baud " + std::string(value) + " is not a standard rate");
  } else if (key == "parity") {
    if (value != "N" && value != "E" && value != "O")
      fail(text, "parity '" + std::string(value) + "' (expected N, E or O)");
    ep.parity = value[0];
  } else if (key == "data") {
    ep.data_bits = parse_int(text, "data", value, 7, 8);
  } else if (key == "stop") {
    ep.stop_bits = parse_int(text, "stop", value, 1, 2);
  } else {
    fail(text, "unknown option '" + std::string(key) + "' (expected baud, parity, data, stop)");
  }
}

}  // namespace

LineEndpoint parse_line_endpoint(std::string_view text) {
  if (text.starts_with("tcp://")) {
    const auto rest = text.substr(6);
    const auto colon = rest.rfind(':');
    if (colon == std::string_view::npos) fail(text, "missing ':PORT' after host");
    LineTcp ep{std::string(rest.substr(0, colon)), 0};
    if (ep.host.size() > 2 && ep.host.front() == '[' && ep.host.back() == ']')
      ep.host = ep.host.substr(1, ep.host.size() - 2);  // [::1]
    if (ep.host.empty()) fail(text, "empty host");
    if (ep.host == "localhost") ep.host = "127.0.0.1";
    // An address literal: a host name would be resolved without a deadline (getaddrinfo).
    in6_addr a6{};
    in_addr a4{};
    if (::inet_pton(AF_INET, ep.host.c_str(), &a4) != 1 &&
        ::inet_pton(AF_INET6, ep.host.c_str(), &a6) != 1)
      fail(text, "host must be an IPv4 or IPv6 address (a name would need DNS without a deadline)");
    ep.port = parse_int(text, "port", rest.substr(colon + 1), 1, 65535);
    return ep;
  }
  if (!text.starts_with("serial:")) fail(text, "scheme must be 'tcp://' or 'serial:'");
  auto rest = text.substr(7);
  const auto q = rest.find('?');
  LineSerial ep;
  ep.device = std::string(rest.substr(0, q));
  if (ep.device.empty() || ep.device[0] != '/') fail(text, "device must be an absolute path");
  if (q == std::string_view::npos) return ep;
  auto opts = rest.substr(q + 1);
  while (!opts.empty()) {
    const auto amp = opts.find('&');
    apply_option(text, ep, opts.substr(0, amp));
    if (amp == std::string_view::npos) break;
    opts.remove_prefix(amp + 1);
  }
  return ep;
}

std::string to_string(const LineEndpoint& ep) {
  if (const auto* t = std::get_if<LineTcp>(&ep))
    return "tcp://" + t->host + ":" + std::to_string(t->port);
  const auto& s = std::get<LineSerial>(ep);
  return "serial:" + s.device + "?baud=" + std::to_string(s.baud) + "&parity=" + s.parity +
         "&data=" + std::to_string(s.data_bits) + "&stop=" + std::to_string(s.stop_bits);
}

}  // namespace station::drivers::ascii
