// Fuzz target: the session log line parser (station/session/session_log.*), which `station
// replay` runs on modbus.log and gpio.log. Input: one line of text.
// Property: no crash or UB; an accepted line, written again by the recorder's formatter, parses
// to the same record (time to the microsecond, device, direction, kind, bytes).
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "station/session/session_log.hpp"
#include "station/session/session_recorder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string line(reinterpret_cast<const char*>(data), size);
  if (line.find('\n') != std::string::npos) return 0;  // one line per call
  const auto r = station::parse_session_line(line);
  if (!r) return 0;
  const auto& a = r.value();
  if (!std::isfinite(a.t_s) || std::abs(a.t_s) > 1e12) return 0;  // outside any session's clock
  station::drivers::TapRecord rec;
  rec.device = a.device;
  rec.direction = a.direction == "tx"   ? station::drivers::TapDirection::tx
                  : a.direction == "rx" ? station::drivers::TapDirection::rx
                                        : station::drivers::TapDirection::event;
  rec.kind = a.kind;
  rec.bytes = a.bytes;
  rec.detail = a.detail;
  const auto again = station::parse_session_line(station::format_session_line(rec, a.t_s));
  station::fuzz::check(again.ok(), "a parsed line does not parse once written again");
  const auto& b = again.value();
  station::fuzz::check(std::abs(b.t_s - a.t_s) <= 1e-6 * std::max(1.0, std::abs(a.t_s)),
                       "time changed");
  station::fuzz::check(
      b.device == a.device && b.direction == a.direction && b.kind == a.kind && b.bytes == a.bytes,
      "a field changed on the round trip");
  return 0;
}
