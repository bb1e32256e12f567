// Which requests a simulated Modbus unit answers, by the unit id (slave address) they carry, as
// the unit is reached: on a serial line, on its own Ethernet port, or behind a TCP-to-RTU
// gateway. Decided from the link, the unit's address and the request alone; no I/O.
//
// Sources: [SL] Modbus over Serial Line v1.02 §2.2 (addresses 1..247; 0 is the broadcast address:
// every slave executes a broadcast write and none replies; a slave answers only its own address).
// [TCP] Modbus Messaging on TCP/IP Implementation Guide v1.0b §4.4.1.2, p. 23 (a server reached
// by its IP address: the unit identifier is "useless", 0xFF is to be used, 0 is also accepted; a
// gateway uses it to forward the request to the slave on its serial line). [AP] Modbus
// Application Protocol v1.1b3 §7 (exception 0x0B: gateway target device failed to respond).
#pragma once

#include <cstdint>

namespace station::sim {

/// Exception 0x0B, gateway target device failed to respond ([AP] §7).
inline constexpr std::uint8_t kGatewayTargetFailed = 0x0B;

/// How a simulated unit is reached.
enum class UnitLink {
  rtu,          ///< on a serial line ([SL] §2.2)
  tcp_device,   ///< on its own Modbus TCP port (the F4T's Ethernet port)
  tcp_gateway,  ///< on the serial line of a TCP-to-RTU gateway
};

/// What the unit (or the gateway in front of it) does with one request.
enum class UnitAnswer {
  serve,          ///< executes it and replies
  broadcast,      ///< a write to unit 0 on a serial line: executed, never answered ([SL] §2.2)
  silence,        ///< not for this unit: no reply at all, the master times out
  gateway_error,  ///< the gateway replies exception 0x0B: nothing answered behind it
};

/// The answer of a unit with address `unit` (1..247) reached over `link` to a request for unit
/// `asked` with function code `function`:
/// - rtu: its own address is served; a write to 0 is a broadcast; anything else is silence;
/// - tcp_device: its own address, 0xFF and 0 are served ([TCP] p. 23: the values for a device
///   addressed by IP); another address is silence (the unit's own address filter, as on its
///   serial port: an assumption to check on the real unit, docs/DEVICES.md);
/// - tcp_gateway: its own address is served; 0 as on the serial line; any other address gets
///   exception 0x0B from the gateway ([AP] §7), after the gateway's own wait.
UnitAnswer unit_answer(UnitLink link, int unit, int asked, std::uint8_t function);

/// "rtu", "tcp device", "tcp gateway".
const char* to_string(UnitLink link);

}  // namespace station::sim
