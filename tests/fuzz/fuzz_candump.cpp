// Fuzz target: the candump log parser (drivers/can/candump_log.*), which reads the CAN logs that
// `station replay` trusts. Input: text, one candump -l line per line.
// Property: no crash or UB; a line that parses is written back by format_candump_line as a line
// that parses to the same record.
#include <linux/can.h>

#include <cstdint>
#include <cstring>
#include <string_view>

#include "drivers/can/candump_log.hpp"
#include "fuzz_check.hpp"

namespace can = station::drivers::can;
using station::fuzz::check;

namespace {

// The ID as it survives a log line. can-utils (lib.c) writes an error frame's ID as
// can_id & (CAN_ERR_MASK | CAN_ERR_FLAG), dropping CAN_EFF_FLAG, and reads an 8-digit ID with
// CAN_ERR_FLAG set as it is: "A0000000#" reads with CAN_EFF_FLAG set and writes back without.
// The parser follows can-utils, so that one bit is not compared for error frames.
canid_t logged_id(canid_t id) {
  return (id & CAN_ERR_FLAG) ? id & (CAN_ERR_MASK | CAN_ERR_FLAG) : id;
}

bool same_record(const can::CandumpRecord& a, const can::CandumpRecord& b) {
  const std::size_t n = a.frame.can_dlc < CAN_MAX_DLEN ? a.frame.can_dlc : CAN_MAX_DLEN;
  // A remote frame carries no data bytes, whatever its DLC.
  const bool rtr = (a.frame.can_id & CAN_RTR_FLAG) != 0;
  return a.time_sec == b.time_sec && a.time_usec == b.time_usec && a.interface == b.interface &&
         logged_id(a.frame.can_id) == logged_id(b.frame.can_id) &&
         a.frame.can_dlc == b.frame.can_dlc &&
         (rtr || std::memcmp(a.frame.data, b.frame.data, n) == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  while (!text.empty()) {
    const auto nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text = nl == text.npos ? std::string_view{} : text.substr(nl + 1);
    const auto r = can::parse_candump_line(line);
    if (!r) continue;
    check(r.value().time_usec <= 999999, "microseconds above 999999 accepted");
    check(r.value().frame.can_dlc <= CAN_MAX_DLEN, "DLC above 8 accepted");
    const std::string again = can::format_candump_line(r.value());
    const auto back = can::parse_candump_line(again);
    check(back.ok(), "formatted line does not parse: '" + again + "'");
    check(same_record(r.value(), back.value()),
          "record changes through format/parse: '" + std::string(line) + "' -> '" + again + "'");
  }
  return 0;
}
