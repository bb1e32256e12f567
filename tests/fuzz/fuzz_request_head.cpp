// Fuzz target: the HTTP request-head rules (station/http/request_rules.*) the server applies to
// bytes from any client before a route or token check. Input: the bytes a client sends.
// Property: no crash, UB or hang; head_end lies within the input and after a line feed; the
// verdict is 0, 400 or 431 with a one-line reason; a Host the rule calls loopback has no
// character outside those of `localhost`, an IP literal and a port.
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.hpp"
#include "station/http/request_rules.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace sh = station::http;
  using station::fuzz::check;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const sh::HeadLimits limits;
  if (const auto end = sh::head_end(bytes)) {
    check(*end <= bytes.size() && *end >= 2 && bytes[*end - 1] == '\n', "head_end out of place");
    const auto v = sh::check_request_head(bytes.substr(0, *end), limits);
    check(v.status == 0 || v.status == 400 || v.status == 431, "unexpected status");
    check(v.reason.find('\n') == std::string::npos, "a reason of more than one line");
  } else if (bytes.size() > limits.max_bytes) {
    const auto v = sh::oversized_head(bytes, limits);
    check(v.status == 414 || v.status == 431, "oversized head: unexpected status");
  }
  const std::string_view host = bytes.substr(0, bytes.find('\n'));
  if (sh::loopback_host(host)) {
    check(host.find_first_not_of("0123456789abcdefABCDEFlhostLHOST.:[]") == std::string::npos,
          "a loopback Host with a character no loopback name has: " + std::string(host));
  }
  return 0;
}
