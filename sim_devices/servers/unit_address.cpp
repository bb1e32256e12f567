// unit_answer: the unit-id rules of a serial unit, a TCP device and a gateway (see the header).
#include "sim_devices/servers/unit_address.hpp"

namespace station::sim {
namespace {

constexpr int kBroadcast = 0;     // [SL] §2.2
constexpr int kTcpDirect = 0xFF;  // [TCP] p. 23
constexpr std::uint8_t kWriteSingle = 0x06, kWriteMultiple = 0x10;

bool is_write(std::uint8_t function) {
  return function == kWriteSingle || function == kWriteMultiple;
}

// A serial line's answer to unit 0: every unit executes a write, none replies.
UnitAnswer on_the_line(int asked, int unit, std::uint8_t function) {
  if (asked == unit) return UnitAnswer::serve;
  if (asked == kBroadcast) return is_write(function) ? UnitAnswer::broadcast : UnitAnswer::silence;
  return UnitAnswer::silence;
}

}  // namespace

UnitAnswer unit_answer(UnitLink link, int unit, int asked, std::uint8_t function) {
  switch (link) {
    case UnitLink::rtu:
      return on_the_line(asked, unit, function);
    case UnitLink::tcp_device:
      return asked == unit || asked == kTcpDirect || asked == kBroadcast ? UnitAnswer::serve
                                                                         : UnitAnswer::silence;
    case UnitLink::tcp_gateway: {
      const UnitAnswer a = on_the_line(asked, unit, function);
      return a == UnitAnswer::silence && asked != kBroadcast ? UnitAnswer::gateway_error : a;
    }
  }
  return UnitAnswer::silence;
}

const char* to_string(UnitLink link) {
  switch (link) {
    case UnitLink::rtu:
      return "rtu";
    case UnitLink::tcp_device:
      return "tcp device";
    case UnitLink::tcp_gateway:
      return "tcp gateway";
  }
  return "?";
}

}  // namespace station::sim
