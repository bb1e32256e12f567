// Modbus request and reply frames on the wire, as a client reads them itself (LibmodbusWire): the
// request framed for its transport, a reply's length told from its first bytes, and the reply
// checked against the request. Why the client frames replies itself: libmodbus 3.1.6 reads a
// reply in steps (src/modbus.c `_modbus_receive_msg`: header, function, meta, data), each a
// select() that waits `response_timeout` for the first step and `byte_timeout` afresh for every
// later one, so a device that drips its reply one byte per 0.3 s never trips a 0.5 s byte
// timeout and holds the call for as long as it drips (issue 34). Framing by the Modbus documents:
// TCP by the MBAP header's length (Modbus Messaging on TCP/IP Implementation Guide v1.0b §3.1.3),
// RTU by the function code (Modbus Application Protocol v1.1b3 §6: byte count after the function
// for reads, 4 bytes for writes 6/16, 1 for an exception) and a CRC-16 (Modbus over Serial Line
// v1.02 §2.5.1.2, §6.2.2). The checks follow libmodbus's `check_confirmation` and the backends'
// `pre_check_confirmation` (modbus-tcp.c: transaction and protocol id; modbus-rtu.c: unit id,
// `_modbus_rtu_check_integrity`: CRC) with its errno values, so translate_modbus_error reads them
// as before. No I/O.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace station::drivers::modbus {

/// Which transport frames the ADU.
enum class Framing : std::uint8_t { tcp, rtu };

/// Bytes before the function code: the MBAP header (7, its unit id last) or the unit id (1).
constexpr std::size_t header_length(Framing f) {
  return f == Framing::tcp ? 7 : 1;
}

/// CRC-16/MODBUS (reflected polynomial 0xA001, initial 0xFFFF; Serial Line v1.02 §6.2.2).
std::uint16_t crc16(std::span<const std::uint8_t> bytes);

/// The frame of a request `adu` (unit id, then the PDU): behind an MBAP header with transaction
/// id `tid` (TCP), or followed by its CRC low byte first (RTU).
std::vector<std::uint8_t> request_frame(Framing f, std::uint16_t tid,
                                        std::span<const std::uint8_t> adu);

/// The whole length of the reply frame that begins with `head`: 0 while more bytes are needed to
/// tell it, -1 when no reply is framed so (a bad MBAP header, a function no reply has).
int reply_frame_length(Framing f, std::span<const std::uint8_t> head);

/// Checks a whole reply frame against its request frame as libmodbus does: 0 when it answers it,
/// else the errno libmodbus sets (EMBBADCRC, EMBBADSLAVE, EMBBADDATA, EMBBADEXC, or
/// MODBUS_ENOBASE + the exception code the device sent).
int check_reply(Framing f, std::span<const std::uint8_t> request,
                std::span<const std::uint8_t> reply);

/// The `count` register values of a read reply already checked by check_reply, into `dest`.
void reply_words(Framing f, std::span<const std::uint8_t> reply, int count, std::uint16_t* dest);

/// The transaction id of a TCP frame (its first two bytes).
inline std::uint16_t transaction_id(std::span<const std::uint8_t> frame) {
  return static_cast<std::uint16_t>((frame[0] << 8) | frame[1]);
}

}  // namespace station::drivers::modbus
