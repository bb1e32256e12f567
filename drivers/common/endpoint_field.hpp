// One field of an endpoint string ("tcp:HOST:PORT", "rtu:/dev/ttyUSB0?baud=19200"), read with an
// error that names the endpoint, the field and the value. Shared by every endpoint grammar.
#pragma once

#include <charconv>
#include <stdexcept>
#include <string>
#include <string_view>

namespace station::drivers {

/// Throws std::invalid_argument "<what> endpoint '<text>': <message>".
[[noreturn]] inline void endpoint_error(std::string_view what, std::string_view text,
                                        const std::string& message) {
  throw std::invalid_argument(std::string(what) + " endpoint '" + std::string(text) +
                              "': " + message);
}

/// `value` as a decimal integer in [lo, hi]; else endpoint_error naming `key`.
inline int endpoint_int(std::string_view what, std::string_view text, std::string_view key,
                        std::string_view value, int lo, int hi) {
  int v = 0;
  auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
  if (ec != std::errc{} || ptr != value.data() + value.size() || value.empty())
    endpoint_error(what, text,
                   std::string(key) + " '" + std::string(value) + "' is not an integer");
  if (v < lo || v > hi)
    endpoint_error(what, text,
                   std::string(key) + " " + std::to_string(v) + " not in " + std::to_string(lo) +
                       ".." + std::to_string(hi));
  return v;
}

}  // namespace station::drivers
