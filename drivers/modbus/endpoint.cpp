// Endpoint string parsing with errors that name the offending part.
#include "drivers/modbus/endpoint.hpp"

#include <charconv>
#include <stdexcept>

#include "drivers/common/endpoint_field.hpp"

namespace station::drivers::modbus {
namespace {

[[noreturn]] void fail(std::string_view text, const std::string& what) {
  endpoint_error("modbus", text, what);
}

int parse_int(std::string_view text, std::string_view key, std::string_view value, int lo, int hi) {
  return endpoint_int("modbus", text, key, value, lo, hi);
}

TcpEndpoint parse_tcp(std::string_view text, std::string_view rest) {
  auto colon = rest.rfind(':');
  if (colon == std::string_view::npos) fail(text, "missing ':PORT' after host");
  TcpEndpoint ep;
  ep.host = std::string(rest.substr(0, colon));
  if (ep.host.empty()) fail(text, "empty host");
  ep.port = parse_int(text, "port", rest.substr(colon + 1), 1, 65535);
  return ep;
}

void apply_rtu_option(std::string_view text, RtuEndpoint& ep, std::string_view kv) {
  auto eq = kv.find('=');
  if (eq == std::string_view::npos) fail(text, "option '" + std::string(kv) + "' lacks '='");
  auto key = kv.substr(0, eq);
  auto value = kv.substr(eq + 1);
  if (key == "baud") {
    ep.baud = parse_int(text, "baud", value, 50, 4000000);
  } else if (key == "parity") {
    if (value != "N" && value != "E" && value != "O")
      fail(text, "parity '" + std::string(value) + "' (expected N, E or O)");
    ep.parity = value[0];
  } else if (key == "data") {
    ep.data_bits = parse_int(text, "data", value, 5, 8);
  } else if (key == "stop") {
    ep.stop_bits = parse_int(text, "stop", value, 1, 2);
  } else {
    fail(text, "unknown option '" + std::string(key) + "' (expected baud, parity, data, stop)");
  }
}

RtuEndpoint parse_rtu(std::string_view text, std::string_view rest) {
  RtuEndpoint ep;
  auto q = rest.find('?');
  ep.device = std::string(rest.substr(0, q));
  if (ep.device.empty() || ep.device[0] != '/') fail(text, "device must be an absolute path");
  if (q == std::string_view::npos) return ep;
  auto opts = rest.substr(q + 1);
  while (!opts.empty()) {
    auto amp = opts.find('&');
    apply_rtu_option(text, ep, opts.substr(0, amp));
    if (amp == std::string_view::npos) break;
    opts.remove_prefix(amp + 1);
  }
  return ep;
}

}  // namespace

Endpoint parse_endpoint(std::string_view text) {
  if (text.starts_with("tcp://")) return parse_tcp(text, text.substr(6));
  if (text.starts_with("rtu:")) return parse_rtu(text, text.substr(4));
  fail(text, "scheme must be 'tcp://' or 'rtu:'");
}

std::string to_string(const Endpoint& ep) {
  if (const auto* t = std::get_if<TcpEndpoint>(&ep))
    return "tcp://" + t->host + ":" + std::to_string(t->port);
  const auto& r = std::get<RtuEndpoint>(ep);
  return "rtu:" + r.device + "?baud=" + std::to_string(r.baud) + "&parity=" + r.parity +
         "&data=" + std::to_string(r.data_bits) + "&stop=" + std::to_string(r.stop_bits);
}

}  // namespace station::drivers::modbus
