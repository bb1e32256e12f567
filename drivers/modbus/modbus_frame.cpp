// Modbus frames on the wire (see modbus_frame.hpp for the documents and libmodbus's functions).
#include "drivers/modbus/modbus_frame.hpp"

#include <modbus/modbus.h>

#include <cerrno>

namespace station::drivers::modbus {
namespace {

constexpr std::size_t kTcpMaxAdu = 260;  // MBAP 7 + PDU 253 (Application Protocol §4.1)
constexpr std::size_t kRtuMaxAdu = 256;  // unit 1 + PDU 253 + CRC 2 (Serial Line §2.5.1)

std::uint16_t u16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}

// Length of a normal reply's PDU after the function code, from the PDU's first bytes (function
// and what follows): 0 while unknown, -1 for a function no reply has (Application Protocol §6).
int pdu_rest(std::span<const std::uint8_t> pdu) {
  if (pdu.empty()) return 0;
  const std::uint8_t fc = pdu[0];
  if ((fc & 0x80) != 0) return 1;  // the exception code
  switch (fc) {
    case 1:                                    // read coils
    case 2:                                    // read discrete inputs
    case 3:                                    // read holding registers
    case 4:                                    // read input registers
    case 23:                                   // read/write registers
      return pdu.size() < 2 ? 0 : 1 + pdu[1];  // byte count, then the bytes
    case 5:                                    // write single coil
    case 6:                                    // write single register
    case 15:                                   // write multiple coils
    case 16:                                   // write multiple registers
      return 4;                                // address and value, or address and quantity
    case 22:                                   // mask write register
      return 6;
    default:
      return -1;
  }
}

// The whole reply length libmodbus's compute_response_length_from_request expects for `request`.
std::size_t expected_length(Framing f, std::span<const std::uint8_t> request) {
  const std::size_t h = header_length(f), crc = f == Framing::rtu ? 2 : 0;
  switch (request[h]) {
    case 3:
    case 4:
    case 23:
      return h + 2 + 2 * std::size_t{u16(request, h + 3)} + crc;
    case 22:
      return h + 7 + crc;
    default:
      return h + 5 + crc;
  }
}

int check_values(Framing f, std::span<const std::uint8_t> request,
                 std::span<const std::uint8_t> reply) {
  const std::size_t h = header_length(f);
  const std::uint8_t fc = reply[h];
  if (reply.size() != expected_length(f, request)) return EMBBADDATA;
  switch (fc) {
    case 3:
    case 4:
    case 23:
      return reply[h + 1] / 2 == u16(request, h + 3) ? 0 : EMBBADDATA;
    case 16:  // address and quantity echoed
      return u16(reply, h + 1) == u16(request, h + 1) && u16(reply, h + 3) == u16(request, h + 3)
                 ? 0
                 : EMBBADDATA;
    case 6:  // address and value echoed
      return u16(reply, h + 1) == u16(request, h + 1) && u16(reply, h + 3) == u16(request, h + 3)
                 ? 0
                 : EMBBADDATA;
    default:
      return 0;
  }
}

}  // namespace

std::uint16_t crc16(std::span<const std::uint8_t> bytes) {
  std::uint16_t crc = 0xFFFF;
  for (std::uint8_t b : bytes) {
    crc ^= b;
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) ? (crc >> 1) ^ 0xA001 : crc >> 1;
  }
  return crc;
}

std::vector<std::uint8_t> request_frame(Framing f, std::uint16_t tid,
                                        std::span<const std::uint8_t> adu) {
  std::vector<std::uint8_t> out;
  if (f == Framing::tcp) {
    const auto len = static_cast<std::uint16_t>(adu.size());  // unit id and PDU
    out = {static_cast<std::uint8_t>(tid >> 8), static_cast<std::uint8_t>(tid & 0xFF), 0, 0,
           static_cast<std::uint8_t>(len >> 8), static_cast<std::uint8_t>(len & 0xFF)};
  }
  out.insert(out.end(), adu.begin(), adu.end());
  if (f == Framing::rtu) {
    const std::uint16_t crc = crc16(adu);
    out.push_back(static_cast<std::uint8_t>(crc & 0xFF));  // low byte first (§6.2.2)
    out.push_back(static_cast<std::uint8_t>(crc >> 8));
  }
  return out;
}

int reply_frame_length(Framing f, std::span<const std::uint8_t> head) {
  if (f == Framing::tcp) {
    if (head.size() < 6) return 0;
    const std::size_t length = u16(head, 4);  // unit id + PDU
    if (head[2] != 0 || head[3] != 0 || length < 2 || 6 + length > kTcpMaxAdu) return -1;
    return static_cast<int>(6 + length);
  }
  const int rest = pdu_rest(head.subspan(std::min<std::size_t>(1, head.size())));
  if (rest <= 0) return rest;
  const std::size_t whole = 2 + static_cast<std::size_t>(rest) + 2;  // unit, fc, rest, CRC
  return whole > kRtuMaxAdu ? -1 : static_cast<int>(whole);
}

int check_reply(Framing f, std::span<const std::uint8_t> request,
                std::span<const std::uint8_t> reply) {
  const std::size_t h = header_length(f);
  if (reply.size() < h + 2) return EMBBADDATA;
  if (f == Framing::tcp) {
    // modbus-tcp.c _modbus_tcp_pre_check_confirmation: transaction id, protocol id 0.
    if (transaction_id(reply) != transaction_id(request) || u16(reply, 2) != 0) return EMBBADDATA;
  } else {
    // modbus-rtu.c: another unit's frame is EMBBADSLAVE (its CRC unchecked), a bad CRC EMBBADCRC.
    if (reply[0] != request[0] && request[0] != 0) return EMBBADSLAVE;
    const std::uint16_t crc = crc16(reply.first(reply.size() - 2));
    if (reply[reply.size() - 2] != (crc & 0xFF) || reply[reply.size() - 1] != (crc >> 8))
      return EMBBADCRC;
  }
  // modbus.c check_confirmation: an exception names the request's function and has one code.
  const std::uint8_t fc = reply[h];
  if ((fc & 0x80) != 0) {
    const std::size_t whole = h + 2 + (f == Framing::rtu ? 2 : 0);
    if (reply.size() != whole || request[h] != (fc & 0x7F)) return EMBBADEXC;
    const int code = reply[h + 1];
    return code < MODBUS_EXCEPTION_MAX ? MODBUS_ENOBASE + code : EMBBADEXC;
  }
  if (fc != request[h]) return EMBBADDATA;
  return check_values(f, request, reply);
}

void reply_words(Framing f, std::span<const std::uint8_t> reply, int count, std::uint16_t* dest) {
  const std::size_t data = header_length(f) + 2;  // function, byte count
  for (int i = 0; i < count; ++i) dest[i] = u16(reply, data + 2 * static_cast<std::size_t>(i));
}

}  // namespace station::drivers::modbus
